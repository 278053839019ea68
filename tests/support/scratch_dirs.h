// Scratch paths a test process makes under the system temp directory with
// its pid in the name (so that ctest -j runs stay apart), removed when the
// process exits: each run would otherwise leave its own behind.
#pragma once

#include <algorithm>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

namespace bb::test {

// Removes `path` (a file, or a directory with its contents) at exit; returns it.
inline std::string removeAtExit(const std::string& path) {
    struct Paths {
        std::vector<std::string> list;
        ~Paths() {
            std::error_code ec;
            for (const std::string& p : list) std::filesystem::remove_all(p, ec);
        }
    };
    static Paths paths;  // one per process (inline function): destroyed at exit
    if (std::find(paths.list.begin(), paths.list.end(), path) == paths.list.end()) paths.list.push_back(path);
    return path;
}

}  // namespace bb::test
