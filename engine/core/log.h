// Minimal leveled logging to stderr. Warnings are also counted so that
// programs can report them in stats.
#pragma once

#include <string>

namespace bb {

enum class LogLevel { Debug = 0, Info = 1, Warning = 2, Error = 3, Quiet = 4 };

void setLogLevel(LogLevel level);
LogLevel logLevel();

void logDebug(const std::string& message);
void logInfo(const std::string& message);
void logWarning(const std::string& message);
void logError(const std::string& message);

int warningCount();

}  // namespace bb
