// hostutil.cpp - helpers shared by the host-side tools.
#include "hostutil.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace pmhost {

void set_err(char *err, size_t errlen, const std::string &msg)
{
    if (err && errlen)
        std::snprintf(err, errlen, "%s", msg.c_str());
}

int write_atomic(const std::string &path, const std::string &text, char *err, size_t errlen)
{
    std::string tmp = path + ".tmp";
    FILE *f = std::fopen(tmp.c_str(), "w");
    if (!f) {
        set_err(err, errlen, path + ": cannot write: " + std::strerror(errno));
        return -1;
    }
    bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size();
    ok = (std::fclose(f) == 0) && ok;
    if (!ok || std::rename(tmp.c_str(), path.c_str()) != 0) {
        int e = errno;
        std::remove(tmp.c_str());
        set_err(err, errlen, path + ": cannot write: " + std::strerror(e));
        return -1;
    }
    return 0;
}

int is_model_file(const std::string &path, char *err, size_t errlen)
{
    std::FILE *f = std::fopen(path.c_str(), "rb");
    if (!f) {
        set_err(err, errlen, path + ": cannot open: " + std::strerror(errno));
        return -1;
    }
    char line[256] = "";
    int model = 0;
    while (std::fgets(line, sizeof line, f)) {
        const char *q = line + std::strspn(line, " \t\r\n");
        if (!*q || *q == '#')
            continue;
        model = std::strncmp(q, "pm-model", 8) == 0;
        break;
    }
    std::fclose(f);
    return model;
}

} // namespace pmhost
