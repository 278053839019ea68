#include "gl/shader.h"

#include <cstring>
#include <regex>
#include <sstream>

#include "gl/shader_sources.h"

namespace bb::gl {
namespace {

GLenum stageOf(const std::string& file) {
    auto ends = [&](const char* ext) {
        size_t n = std::strlen(ext);
        return file.size() >= n && file.compare(file.size() - n, n, ext) == 0;
    };
    if (ends(".vert")) return GL_VERTEX_SHADER;
    if (ends(".geom")) return GL_GEOMETRY_SHADER;
    if (ends(".frag")) return GL_FRAGMENT_SHADER;
    if (ends(".comp")) return GL_COMPUTE_SHADER;
    return 0;
}

// "3:12(5): error: ..." (Mesa) or "ERROR: 3:12: ..." -> "lib/x.glsl:12(5): error: ..."
std::string mapLog(const std::string& log) {
    static const std::regex sourceRef(R"((^|\s)(\d+):(\d+))");
    std::string out;
    std::istringstream in(log);
    std::string line;
    while (std::getline(in, line)) {
        std::smatch m;
        if (std::regex_search(line, m, sourceRef)) {
            int id = std::stoi(m[2].str());
            if (id >= 0 && id < SHADER_SOURCE_COUNT)
                line = m.prefix().str() + m[1].str() + SHADER_SOURCES[id].name + ":" + m[3].str() + m.suffix().str();
        }
        out += line + "\n";
    }
    return out;
}

std::string oneLine(std::string s) {
    for (char& c : s)
        if (c == '\n') c = ';';
    while (!s.empty() && (s.back() == ';' || s.back() == ' ')) s.pop_back();
    return s;
}

}  // namespace

const char* shaderSource(const std::string& file) {
    for (int i = 0; i < SHADER_SOURCE_COUNT; ++i)
        if (file == SHADER_SOURCES[i].name) return SHADER_SOURCES[i].text;
    return nullptr;
}

Expected<Program> buildProgram(const std::vector<std::string>& files, const std::string& defines) {
    std::string label;
    for (const auto& f : files) label += (label.empty() ? "" : "+") + f;
    GLuint program = glCreateProgram();
    Program owner = Program::adoptName(program, label);
    std::vector<GLuint> shaders;
    auto cleanup = [&] {
        for (GLuint s : shaders) glDeleteShader(s);
    };
    for (const auto& file : files) {
        const char* text = shaderSource(file);
        GLenum stage = stageOf(file);
        if (!text || !stage) {
            cleanup();
            return Status::error("shader " + file + ": not embedded or unknown stage");
        }
        std::string source = text;
        size_t eol = source.find('\n');
        if (!defines.empty() && eol != std::string::npos && source.rfind("#version", 0) == 0)
            source.insert(eol + 1, defines);
        GLuint shader = glCreateShader(stage);
        shaders.push_back(shader);
        glObjectLabel(GL_SHADER, shader, -1, file.c_str());
        const char* src = source.c_str();
        glShaderSource(shader, 1, &src, nullptr);
        glCompileShader(shader);
        GLint ok = 0;
        glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
        if (!ok) {
            GLint n = 0;
            glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &n);
            std::string log(size_t(std::max(n, 1)), '\0');
            glGetShaderInfoLog(shader, n, nullptr, log.data());
            cleanup();
            return Status::error("shader " + file + " failed to compile: " + oneLine(mapLog(log.c_str())));
        }
        glAttachShader(program, shader);
    }
    glLinkProgram(program);
    cleanup();
    GLint ok = 0;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    if (!ok) {
        GLint n = 0;
        glGetProgramiv(program, GL_INFO_LOG_LENGTH, &n);
        std::string log(size_t(std::max(n, 1)), '\0');
        glGetProgramInfoLog(program, n, nullptr, log.data());
        return Status::error("program " + label + " failed to link: " + oneLine(mapLog(log.c_str())));
    }
    return owner;
}

}  // namespace bb::gl
