#include "core/log.h"

#include <atomic>
#include <cstdio>

namespace bb {
namespace {
std::atomic<int> gLevel{static_cast<int>(LogLevel::Info)};
std::atomic<int> gWarnings{0};

void emit(LogLevel level, const char* tag, const std::string& message) {
    if (static_cast<int>(level) < gLevel.load()) return;
    std::fprintf(stderr, "bundlebake: %s%s\n", tag, message.c_str());
}
}  // namespace

void setLogLevel(LogLevel level) { gLevel = static_cast<int>(level); }
LogLevel logLevel() { return static_cast<LogLevel>(gLevel.load()); }
void logDebug(const std::string& m) { emit(LogLevel::Debug, "debug: ", m); }
void logInfo(const std::string& m) { emit(LogLevel::Info, "", m); }
void logWarning(const std::string& m) { ++gWarnings; emit(LogLevel::Warning, "warning: ", m); }
void logError(const std::string& m) { emit(LogLevel::Error, "error: ", m); }
int warningCount() { return gWarnings.load(); }

}  // namespace bb
