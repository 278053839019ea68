// Status and Expected<T>: how bad input travels up to the program, which prints
// one line and exits non-zero. Invariants use CHECK (check.h) instead.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <variant>

namespace bb {

class Status {
public:
    Status() = default;
    static Status ok() { return {}; }
    static Status error(std::string message) {
        Status s;
        s.message_ = std::move(message);
        s.failed_ = true;
        return s;
    }
    bool isOk() const { return !failed_; }
    explicit operator bool() const { return isOk(); }
    const std::string& message() const { return message_; }

private:
    std::string message_;
    bool failed_ = false;
};

// A value or an error message. Usage:
//   Expected<Scene> s = loadScene(path, opts);
//   if (!s) { fprintf(stderr, "%s\n", s.error().c_str()); return 1; }
template <class T>
class Expected {
public:
    Expected(T value) : v_(std::move(value)) {}
    Expected(Status status) : v_(status.message()) {}
    static Expected failure(std::string message) { return Expected(Status::error(std::move(message))); }

    bool hasValue() const { return v_.index() == 0; }
    explicit operator bool() const { return hasValue(); }
    T& value() & { return std::get<0>(v_); }
    const T& value() const& { return std::get<0>(v_); }
    T&& value() && { return std::get<0>(std::move(v_)); }
    T* operator->() { return &value(); }
    const T* operator->() const { return &value(); }
    T& operator*() & { return value(); }
    const T& operator*() const& { return value(); }
    const std::string& error() const { return std::get<1>(v_); }
    Status status() const { return hasValue() ? Status::ok() : Status::error(error()); }

private:
    std::variant<T, std::string> v_;
};

}  // namespace bb
