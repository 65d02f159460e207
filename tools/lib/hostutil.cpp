// hostutil.cpp - helpers shared by the host-side tools.
#include "hostutil.hpp"

#include <cerrno>
#include <cstdarg>
#include <cstdio>
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <mutex>
#include <system_error>
#include <thread>

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

std::string fmt(const char *f, ...)
{
    va_list ap, aq;
    va_start(ap, f);
    va_copy(aq, ap);
    char buf[512];
    int n = std::vsnprintf(buf, sizeof buf, f, ap);
    va_end(ap);
    std::string out;
    if (n < 0) {
        /* an encoding error: nothing */
    } else if ((size_t)n < sizeof buf) {
        out.assign(buf, (size_t)n);
    } else {
        out.resize((size_t)n + 1);
        std::vsnprintf(&out[0], out.size(), f, aq);
        out.resize((size_t)n);
    }
    va_end(aq);
    return out;
}

std::string joined(const std::vector<int> &v)
{
    std::string s;
    for (size_t k = 0; k < v.size(); k++)
        s += (k ? ", " : "") + std::to_string(v[k]);
    return s;
}

std::string xml_escape(const std::string &s)
{
    std::string o;
    for (size_t i = 0; i < s.size(); i++) {
        unsigned char c = (unsigned char)s[i];
        if (c == '&') o += "&amp;";
        else if (c == '<') o += "&lt;";
        else if (c == '>') o += "&gt;";
        else if (c == '"') o += "&quot;";
        else if (c == '\'') o += "&apos;";
        else if (c < 0x20 || c == 0x7f) o += ' ';
        else if (c < 0x80) o += (char)c;
        else {
            size_t n = c >= 0xC2 && c <= 0xDF ? 1 : c >= 0xE0 && c <= 0xEF ? 2 : c >= 0xF0 && c <= 0xF4 ? 3 : 0;
            bool ok = n > 0 && i + n < s.size();
            for (size_t k = 1; ok && k <= n; k++)
                ok = ((unsigned char)s[i + k] & 0xC0) == 0x80;
            unsigned char c1 = ok ? (unsigned char)s[i + 1] : 0;
            ok = ok && !(c == 0xE0 && c1 < 0xA0) && !(c == 0xED && c1 >= 0xA0) &&
                 !(c == 0xF0 && c1 < 0x90) && !(c == 0xF4 && c1 >= 0x90);
            if (ok) { o.append(s, i, n + 1); i += n; }
            else o += '?';
        }
    }
    return o;
}

std::vector<int> all_of(size_t n)
{
    std::vector<int> v(n);
    for (size_t i = 0; i < n; i++)
        v[i] = (int)i;
    return v;
}

unsigned host_threads()
{
    const char *e = std::getenv("PMFIT_THREADS");
    if (e && *e) {
        char *end = nullptr;
        long v = std::strtol(e, &end, 10);
        if (end && *end == 0 && v >= 1 && v <= 64)
            return (unsigned)v;
    }
    unsigned h = std::thread::hardware_concurrency();
    return h < 1 ? 1 : h > 8 ? 8 : h;
}

void parallel_for(size_t n, const std::function<void(size_t)> &f)
{
    unsigned t = host_threads();
    if (t > n)
        t = (unsigned)n;
    if (t <= 1) {
        for (size_t i = 0; i < n; i++)
            f(i);
        return;
    }
    std::atomic<size_t> next(0);
    std::exception_ptr first;
    std::mutex m;
    auto work = [&]() {
        for (size_t i; (i = next++) < n;) {
            try {
                f(i);
            } catch (...) {
                std::lock_guard<std::mutex> g(m);
                if (!first)
                    first = std::current_exception();
            }
        }
    };
    std::vector<std::thread> pool;
    for (unsigned k = 1; k < t; k++) {
        try {
            pool.emplace_back(work);
        } catch (const std::system_error &) {
            break; // no more threads: the ones there share the work
        }
    }
    work();
    for (std::thread &th : pool)
        th.join();
    if (first)
        std::rethrow_exception(first);
}

} // namespace pmhost
