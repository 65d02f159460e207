// hostutil.cpp - helpers shared by the host-side tools.
#include "hostutil.hpp"

#include <cctype>
#include <cmath>
#include <cerrno>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
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

// The file a path names, for a rename onto it: an existing file's real
// path (symbolic links followed, also /proc's links to open files); where
// nothing exists yet, a dangling symbolic link's target (up to 32 links),
// else the path itself.
static std::string link_target(const std::string &path)
{
    char *real = realpath(path.c_str(), nullptr);
    if (real) {
        std::string r(real);
        std::free(real);
        return r;
    }
    std::string p = path;
    for (int hop = 0; hop < 32; hop++) {
        struct stat st;
        if (lstat(p.c_str(), &st) != 0 || !S_ISLNK(st.st_mode))
            return p;
        char buf[4096];
        ssize_t n = readlink(p.c_str(), buf, sizeof buf);
        if (n <= 0 || (size_t)n >= sizeof buf)
            return p;
        std::string to(buf, (size_t)n);
        if (to[0] != '/') {
            size_t slash = p.rfind('/');
            to = (slash == std::string::npos ? std::string() : p.substr(0, slash + 1)) + to;
        }
        p = to;
    }
    return p;
}

static int write_in_place(const std::string &path, const std::string &text, char *err,
                          size_t errlen)
{
    FILE *f = std::fopen(path.c_str(), "w");
    if (!f) {
        set_err(err, errlen, path + ": cannot write: " + std::strerror(errno));
        return -1;
    }
    bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size();
    int e = errno;
    if (std::fclose(f) != 0 && ok) {
        ok = false;
        e = errno;
    }
    if (!ok) {
        set_err(err, errlen, path + ": cannot write: " + std::strerror(e ? e : EIO));
        return -1;
    }
    return 0;
}

int write_atomic(const std::string &path, const std::string &text, char *err, size_t errlen)
{
    // A symbolic link keeps pointing where it did: the file it names is
    // written (replaced through its own temporary).  What is not a regular
    // file (a device such as /dev/stdout's target or /dev/null, a FIFO, a
    // file of /proc) is written in place: a rename would replace the node
    // itself.
    struct stat st;
    bool exists = stat(path.c_str(), &st) == 0;
    if (exists && !S_ISREG(st.st_mode))
        return write_in_place(path, text, err, errlen);
    const std::string target = link_target(path);
    if (exists && access(target.c_str(), W_OK) != 0) { // (a file made read-only stays)
        set_err(err, errlen, path + ": cannot write: " + std::strerror(errno));
        return -1;
    }
    // A temporary of a name of its own beside the target (O_EXCL: never a
    // file that is already there, and never one another process writes at
    // the same time), then a rename over the target: a failure leaves the
    // target as it was.
    static std::atomic<unsigned> serial(0);
    std::string tmp;
    int fd = -1;
    for (int attempt = 0; attempt < 100 && fd < 0; attempt++) {
        char sfx[64];
        std::snprintf(sfx, sizeof sfx, ".tmp%ld.%u", (long)getpid(), serial++);
        tmp = target + sfx;
        fd = open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC,
                  exists ? (st.st_mode & 07777) : 0666);
        if (fd < 0 && errno != EEXIST)
            break;
    }
    if (fd < 0) {
        set_err(err, errlen, path + ": cannot write: " + std::strerror(errno));
        return -1;
    }
    if (exists)
        (void)fchmod(fd, st.st_mode & 07777); // (open's mode passes the umask)
    size_t done = 0;
    int e = 0;
    while (done < text.size()) {
        ssize_t n = ::write(fd, text.data() + done, text.size() - done);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0) {
            e = n < 0 ? errno : EIO;
            break;
        }
        done += (size_t)n;
    }
    if (close(fd) != 0 && !e)
        e = errno;
    if (!e && std::rename(tmp.c_str(), target.c_str()) != 0)
        e = errno;
    if (e) {
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
    // The first line that is not blank or a comment, read whole (a comment
    // longer than a buffer -- pmfit's own undetermined-fit warning is ~290
    // bytes -- left its tail to be taken for that line, and the model file
    // for a run); at most 64 kB of a line.
    int model = 0;
    std::string line;
    int ch = 0;
    while (ch != EOF) {
        line.clear();
        while ((ch = std::fgetc(f)) != EOF && ch != '\n')
            if (line.size() < 65536)
                line += (char)ch;
        const char *q = line.c_str() + std::strspn(line.c_str(), " \t\r");
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

std::string shell_word(const std::string &s)
{
    static const char safe[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789"
                               "_-./:=,+@%^";
    if (!s.empty() && s.find_first_not_of(safe) == std::string::npos)
        return s;
    if (s.find('\'') == std::string::npos)
        return "'" + s + "'";
    if (s.find_first_of("\"$`\\!") == std::string::npos)
        return "\"" + s + "\"";
    std::string o = "'";
    for (char c : s)
        o += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return o + "'";
}

std::string add_word(const std::string &spec)
{
    return spec.find('\'') == std::string::npos ? "'" + spec + "'" : shell_word(spec);
}

bool valid_column_name(const std::string &s)
{
    if (s.empty() || !(std::isalpha((unsigned char)s[0]) || s[0] == '_'))
        return false;
    for (char c : s)
        if (!(std::isalnum((unsigned char)c) || c == '_' || c == '.' || c == '-'))
            return false;
    return true;
}

// d^T C^-1 d over the terms `s` (C row-major, n x n), by Cholesky; NaN
// where C restricted to them is not positive definite.
double quad_form(const std::vector<double> &d, const std::vector<double> &C, int n,
                 const std::vector<int> &s)
{
    const size_t m = s.size();
    std::vector<double> L(m * m, 0.0), y(m, 0.0);
    for (size_t i = 0; i < m; i++)
        for (size_t j = 0; j <= i; j++) {
            double v = C[(size_t)s[i] * (size_t)n + (size_t)s[j]];
            for (size_t k = 0; k < j; k++)
                v -= L[i * m + k] * L[j * m + k];
            if (i == j) {
                if (!(v > 0))
                    return NAN;
                L[i * m + i] = std::sqrt(v);
            } else {
                L[i * m + j] = v / L[j * m + j];
            }
        }
    double q = 0;
    for (size_t i = 0; i < m; i++) {
        double v = d[(size_t)s[i]];
        for (size_t k = 0; k < i; k++)
            v -= L[i * m + k] * y[k];
        y[i] = v / L[i * m + i];
        q += y[i] * y[i];
    }
    return q;
}

} // namespace pmhost
