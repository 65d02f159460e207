/*
**  fz_file.h - files for the file-reading harnesses: the fuzzer's bytes as
**  an in-memory file (memfd_create, read through /proc/self/fd/N), and a
**  private scratch directory for what the harnesses write.
**
**  The including translation unit must define _GNU_SOURCE before its first
**  #include (memfd_create).
*/
#ifndef PMFZ_FILE_H
#define PMFZ_FILE_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

/* Write the bytes to a new memory file; returns its descriptor (or -1) and
** its path in path[len]. */
static inline int pmfz_memfile(const void *data, size_t size, char *path, size_t len)
{
    const char *p = (const char *)data;
    int fd = memfd_create("pmfz", MFD_CLOEXEC);
    if (fd < 0)
        return -1;
    while (size > 0) {
        ssize_t w = write(fd, p, size);
        if (w <= 0) {
            close(fd);
            return -1;
        }
        p += w;
        size -= (size_t)w;
    }
    snprintf(path, len, "/proc/self/fd/%d", fd);
    return fd;
}

static char pmfz_scratch_dir[64];

static inline void pmfz_scratch_cleanup(void)
{
    if (pmfz_scratch_dir[0])
        rmdir(pmfz_scratch_dir);
}

/* A directory of this process's own (made once, removed at exit when
** empty); NULL if it cannot be made. */
static inline const char *pmfz_scratch(void)
{
    if (!pmfz_scratch_dir[0]) {
        char tmpl[] = "/tmp/pmfz_XXXXXX";
        if (!mkdtemp(tmpl))
            return NULL;
        strcpy(pmfz_scratch_dir, tmpl);
        atexit(pmfz_scratch_cleanup);
    }
    return pmfz_scratch_dir;
}

#endif
