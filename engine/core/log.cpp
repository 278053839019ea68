#include "core/log.h"

#include <atomic>
#include <cstdio>
#include <mutex>
#include <vector>

namespace bb {
namespace {
std::atomic<int> gLevel{static_cast<int>(LogLevel::Info)};
std::atomic<int> gWarnings{0};
std::mutex gHeldMutex;
bool gHolding = false;
std::vector<std::string> gHeld;  // formatted lines, in order

void emit(LogLevel level, const char* tag, const std::string& message) {
    if (static_cast<int>(level) < gLevel.load()) return;
    const std::string line = std::string("bundlebake: ") + tag + message + "\n";
    if (level == LogLevel::Info || level == LogLevel::Warning) {
        std::lock_guard<std::mutex> lock(gHeldMutex);
        if (gHolding) {
            gHeld.push_back(line);
            return;
        }
    }
    std::fputs(line.c_str(), stderr);
}
}  // namespace

void holdLogMessages() {
    std::lock_guard<std::mutex> lock(gHeldMutex);
    gHolding = true;
}
void releaseHeldLogMessages() {
    std::lock_guard<std::mutex> lock(gHeldMutex);
    for (const std::string& line : gHeld) std::fputs(line.c_str(), stderr);
    gHeld.clear();
    gHolding = false;
}
void discardHeldLogMessages() {
    std::lock_guard<std::mutex> lock(gHeldMutex);
    gHeld.clear();
    gHolding = false;
}

void setLogLevel(LogLevel level) { gLevel = static_cast<int>(level); }
LogLevel logLevel() { return static_cast<LogLevel>(gLevel.load()); }
void logDebug(const std::string& m) { emit(LogLevel::Debug, "debug: ", m); }
void logInfo(const std::string& m) { emit(LogLevel::Info, "", m); }
void logWarning(const std::string& m) { ++gWarnings; emit(LogLevel::Warning, "warning: ", m); }
void logError(const std::string& m) { emit(LogLevel::Error, "error: ", m); }
int warningCount() { return gWarnings.load(); }

}  // namespace bb
