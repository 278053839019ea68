// Runs the bundlebake CLI (BUNDLEBAKE_CLI, the built binary's path) as a
// child process and captures its exit code, stdout and stderr; temp
// directories that remove themselves. Header-only, POSIX.
#pragma once

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace bb::test {

struct CliResult {
    int exitCode = -1;   // -1 when killed by a signal
    std::string out, err;
    std::vector<std::string> errLines() const {
        std::vector<std::string> lines;
        std::istringstream in(err);
        for (std::string line; std::getline(in, line);) lines.push_back(line);
        return lines;
    }
};

inline std::string readFileBytes(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

// A fresh directory under the system temp dir, removed (with its contents) on destruction.
class TempDir {
public:
    explicit TempDir(const std::string& tag) {
        std::string pattern = (std::filesystem::temp_directory_path() / ("bundlebake-test-" + tag + "-XXXXXX")).string();
        std::vector<char> buf(pattern.begin(), pattern.end());
        buf.push_back('\0');
        if (::mkdtemp(buf.data())) path_ = buf.data();
    }
    ~TempDir() {
        std::error_code ec;
        if (!path_.empty()) std::filesystem::remove_all(path_, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    const std::filesystem::path& path() const { return path_; }
    std::string operator/(const std::string& name) const { return (path_ / name).string(); }
    bool ok() const { return !path_.empty(); }

private:
    std::filesystem::path path_;
};

// Runs `program` with `args` (no shell), stdout and stderr to files in `scratch`.
inline CliResult runProgram(std::string exe, const std::vector<std::string>& args, const TempDir& scratch) {
    CliResult r;
    const std::string outPath = scratch / "cli-stdout.txt", errPath = scratch / "cli-stderr.txt";
    std::vector<char*> argv;
    std::vector<std::string> copy = args;
    argv.push_back(exe.data());
    for (auto& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    pid_t pid = ::fork();
    if (pid == 0) {
        // only async-signal-safe calls between fork and exec
        int o = ::open(outPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        int e = ::open(errPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (o < 0 || e < 0 || ::dup2(o, 1) < 0 || ::dup2(e, 2) < 0) ::_exit(127);
        ::execv(exe.c_str(), argv.data());
        ::_exit(127);
    }
    if (pid < 0) {
        r.err = "fork failed";
        return r;
    }
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = readFileBytes(outPath);
    r.err = readFileBytes(errPath);
    std::error_code ec;
    std::filesystem::remove(outPath, ec);
    std::filesystem::remove(errPath, ec);
    return r;
}

// Runs BUNDLEBAKE_CLI with `args`.
inline CliResult runCli(const std::vector<std::string>& args, const TempDir& scratch) {
    return runProgram(BUNDLEBAKE_CLI, args, scratch);
}

}  // namespace bb::test
