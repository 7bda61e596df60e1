/* A stand-in for a full or failing disk, preloaded into a program under test
 * (LD_PRELOAD=libknit_fail_io.so): write(2), writev(2) and pwrite(2) to a file whose name
 * contains $KNIT_FAIL_WRITE fail with ENOSPC, fsync(2) of a file whose name contains
 * $KNIT_FAIL_FSYNC fails with EIO. With $KNIT_LOG_REMOVE set to a file, every path that
 * remove(3), unlink(2), unlinkat(2) or rmdir(2) removed is appended to it, one per line, in order
 * (the names as the program passed them; unlinkat's relative to its directory's path). Without
 * these variables it changes nothing.
 *
 * A file-size limit (RLIMIT_FSIZE) cannot stand in here: it limits each file's size, so a
 * small file (a summary of 180 bytes, buffered by std::ofstream until it is closed) always
 * fits, and a full disk that refuses that last write at close went unnoticed (session 34). */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <sys/uio.h>
#include <unistd.h>

/* True if fd is a file whose name (last path component) contains $var. */
static int fails(int fd, const char* var) {
  const char* want = getenv(var);
  if (!want || !*want) return 0;
  char link[64], path[4096];
  snprintf(link, sizeof link, "/proc/self/fd/%d", fd);
  const int saved = errno;
  const ssize_t n = readlink(link, path, sizeof path - 1);
  errno = saved;
  if (n <= 0) return 0;
  path[n] = '\0';
  const char* base = strrchr(path, '/');
  return strstr(base ? base + 1 : path, want) != NULL;
}

#define REAL(name, type) ((type)dlsym(RTLD_NEXT, name))

ssize_t write(int fd, const void* buf, size_t count) {
  if (fails(fd, "KNIT_FAIL_WRITE")) {
    errno = ENOSPC;
    return -1;
  }
  return REAL("write", ssize_t (*)(int, const void*, size_t))(fd, buf, count);
}

ssize_t writev(int fd, const struct iovec* iov, int iovcnt) {
  if (fails(fd, "KNIT_FAIL_WRITE")) {
    errno = ENOSPC;
    return -1;
  }
  return REAL("writev", ssize_t (*)(int, const struct iovec*, int))(fd, iov, iovcnt);
}

ssize_t pwrite(int fd, const void* buf, size_t count, off_t offset) {
  if (fails(fd, "KNIT_FAIL_WRITE")) {
    errno = ENOSPC;
    return -1;
  }
  return REAL("pwrite", ssize_t (*)(int, const void*, size_t, off_t))(fd, buf, count, offset);
}

ssize_t pwrite64(int fd, const void* buf, size_t count, off_t offset) {
  if (fails(fd, "KNIT_FAIL_WRITE")) {
    errno = ENOSPC;
    return -1;
  }
  return REAL("pwrite64", ssize_t (*)(int, const void*, size_t, off_t))(fd, buf, count, offset);
}

int fsync(int fd) {
  if (fails(fd, "KNIT_FAIL_FSYNC")) {
    errno = EIO;
    return -1;
  }
  return REAL("fsync", int (*)(int))(fd);
}

/* Appends `dir/name` (or `name` alone if dir is NULL) and a newline to $KNIT_LOG_REMOVE. */
static void log_remove(const char* dir, const char* name) {
  const char* log = getenv("KNIT_LOG_REMOVE");
  if (!log || !*log) return;
  const int saved = errno;
  char line[8192];
  const int n = dir ? snprintf(line, sizeof line, "%s/%s\n", dir, name)
                    : snprintf(line, sizeof line, "%s\n", name);
  const int fd = open(log, O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd >= 0 && n > 0 && n < (int)sizeof line) {
    REAL("write", ssize_t (*)(int, const void*, size_t))(fd, line, (size_t)n);
  }
  if (fd >= 0) close(fd);
  errno = saved;
}

int remove(const char* path) {
  const int rc = REAL("remove", int (*)(const char*))(path);
  if (rc == 0) log_remove(NULL, path);
  return rc;
}

int unlink(const char* path) {
  const int rc = REAL("unlink", int (*)(const char*))(path);
  if (rc == 0) log_remove(NULL, path);
  return rc;
}

int rmdir(const char* path) {
  const int rc = REAL("rmdir", int (*)(const char*))(path);
  if (rc == 0) log_remove(NULL, path);
  return rc;
}

int unlinkat(int dirfd, const char* path, int flags) {
  char dir[4096] = "";
  if (path[0] != '/' && dirfd != AT_FDCWD) {
    char link[64];
    snprintf(link, sizeof link, "/proc/self/fd/%d", dirfd);
    const ssize_t n = readlink(link, dir, sizeof dir - 1);
    dir[n > 0 ? n : 0] = '\0';
  }
  const int rc = REAL("unlinkat", int (*)(int, const char*, int))(dirfd, path, flags);
  if (rc == 0) log_remove(dir[0] ? dir : NULL, path);
  return rc;
}
