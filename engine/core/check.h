// Always-on invariant checks that print both operands, and debug-only DCHECK.
// A failed CHECK is a bug in bundlebake, never a user error: it aborts.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>

namespace bb::detail {
[[noreturn]] inline void checkFailed(const char* file, int line, const std::string& what) {
    std::fprintf(stderr, "bundlebake: internal error: %s:%d: CHECK failed: %s\n", file, line, what.c_str());
    std::fflush(stderr);
    std::abort();
}
template <class A, class B>
std::string describeOperands(const char* expr, const A& a, const B& b) {
    std::ostringstream os;
    os << expr << " (" << a << " vs " << b << ")";
    return os.str();
}
}  // namespace bb::detail

#define CHECK(cond) \
    do { if (!(cond)) ::bb::detail::checkFailed(__FILE__, __LINE__, #cond); } while (0)
#define CHECK_OP_(a, b, op)                                                                    \
    do {                                                                                       \
        const auto& checkA_ = (a);                                                             \
        const auto& checkB_ = (b);                                                             \
        if (!(checkA_ op checkB_))                                                             \
            ::bb::detail::checkFailed(__FILE__, __LINE__,                                      \
                ::bb::detail::describeOperands(#a " " #op " " #b, checkA_, checkB_));          \
    } while (0)
#define CHECK_EQ(a, b) CHECK_OP_(a, b, ==)
#define CHECK_NE(a, b) CHECK_OP_(a, b, !=)
#define CHECK_LT(a, b) CHECK_OP_(a, b, <)
#define CHECK_LE(a, b) CHECK_OP_(a, b, <=)
#define CHECK_GT(a, b) CHECK_OP_(a, b, >)
#define CHECK_GE(a, b) CHECK_OP_(a, b, >=)

#ifdef NDEBUG
#define DCHECK(cond) do { (void)sizeof(cond); } while (0)
#else
#define DCHECK(cond) CHECK(cond)
#endif
