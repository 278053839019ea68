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

// Holding: while held, info and warning lines are kept instead of printed
// (errors and debug lines print at once). A program that refuses its input
// in one line holds until the input is accepted, then releases (prints the
// kept lines in order) or, on error, discards them: bad input gives its one
// error line alone. warningCount() counts held warnings too.
void holdLogMessages();
void releaseHeldLogMessages();
void discardHeldLogMessages();

// Holds for its scope; discards on destruction unless released.
class LogHold {
public:
    LogHold() { holdLogMessages(); }
    ~LogHold() { discardHeldLogMessages(); }
    LogHold(const LogHold&) = delete;
    LogHold& operator=(const LogHold&) = delete;
    void release() { releaseHeldLogMessages(); }
};

}  // namespace bb
