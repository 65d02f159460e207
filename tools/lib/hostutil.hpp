// hostutil.hpp - small helpers shared by the host-side tools (C++).
#ifndef PM_HOSTUTIL_HPP
#define PM_HOSTUTIL_HPP

#include <cstddef>
#include <string>
#include <functional>
#include <vector>

namespace pmhost {

// Write text to path through a temporary beside it ("path.tmpPID.N",
// created anew, never an existing file) and a rename, so that a failure
// never leaves a half-written file.  A symbolic link is followed (the file
// it names is replaced, the link stays); what is not a regular file (a
// device, a FIFO, /dev/stdout's target) is written in place; an existing
// file this process may not write is refused.  Returns 0, or -1 with a
// message in err ("path: cannot write: reason").
int write_atomic(const std::string &path, const std::string &text, char *err, size_t errlen);

// Is the file at path a model file (its first line that is not blank or a
// '#' comment starts "pm-model") rather than a run?  Returns 1 or 0, or -1
// with "path: cannot open: reason" in err.  (pmfit compare OLD, report
// --compare OLD: OLD is either.)
// s as one word of a POSIX shell command line: as it is where every
// character is safe, else quoted ('...', or "..." around a ', or '...'
// with each ' written '\'').  For the commands the tools print to be
// copied (a run's path with a space, a '<').
std::string shell_word(const std::string &s);
// An --add EFFECT as pmfit prints it: always quoted (EFFECT may hold ').
std::string add_word(const std::string &spec);

// A column name of the named-column format (docs/formats.md): letters,
// digits, '_', '.', '-', not empty, a letter or '_' first.
bool valid_column_name(const std::string &s);

int is_model_file(const std::string &path, char *err, size_t errlen);

// printf into a std::string, of any length.
std::string fmt(const char *f, ...) __attribute__((format(printf, 1, 2)));

// Escape text for XML and HTML (SVG figures, the report page): & < > " '
// as entities, control characters as spaces, invalid UTF-8 bytes as '?'
// (valid UTF-8 passes through).
std::string xml_escape(const std::string &s);

// The numbers of v as "1, 2, 3" (file lines in a report: text, or a JSON
// array between brackets).
std::string joined(const std::vector<int> &v);

// Copy msg into err (truncated, NUL-terminated) if err is not NULL.
void set_err(char *err, size_t errlen, const std::string &msg);

// The indices 0 .. n-1 (every observation of a run).
std::vector<int> all_of(size_t n);

// f(0) ... f(n-1), each once, on up to host_threads() threads (the calls
// must be independent: each writes only its own results).  The results do
// not depend on the number of threads.  The first exception a call throws
// is rethrown here once every thread has ended.
void parallel_for(size_t n, const std::function<void(size_t)> &f);
// How many threads parallel_for uses: PMFIT_THREADS where set (1: none),
// else the machine's hardware threads, at most 8.
unsigned host_threads();

// d^T C^-1 d over the terms `s` (C row-major, n x n), by Cholesky; NaN
// where C restricted to them is not positive definite (compare's tests of
// moved terms, explain's measured effects).
double quad_form(const std::vector<double> &d, const std::vector<double> &C, int n,
                 const std::vector<int> &s);

} // namespace pmhost

#endif
