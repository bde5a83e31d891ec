#include "impinge/core/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "impinge/core/error.hpp"

namespace impinge {

namespace {
std::atomic<unsigned> counter{0};

std::string reason() { return std::strerror(errno); }
}  // namespace

AtomicFile::AtomicFile(std::string path) : path_(std::move(path)) {
  for (int attempt = 0; attempt < 100; ++attempt) {
    temp_ = path_ + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
    const int fd = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, 0644);
    if (fd >= 0) {
      ::close(fd);
      return;
    }
    if (errno != EEXIST) throw Error(path_ + ": cannot create a file there (" + reason() + ")");
  }
  throw Error(path_ + ": cannot create a temporary file beside it");
}

AtomicFile::~AtomicFile() {
  if (!committed_) ::unlink(temp_.c_str());
}

void AtomicFile::commit() {
  if (::rename(temp_.c_str(), path_.c_str()) != 0) {
    const std::string why = reason();
    ::unlink(temp_.c_str());
    committed_ = true;
    throw Error(path_ + ": cannot write (" + why + ")");
  }
  committed_ = true;
}

void write_file_atomically(const std::string& path, std::string_view bytes) {
  AtomicFile f(path);
  const int fd = ::open(f.temp_path().c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC | O_NOFOLLOW);
  if (fd < 0) throw Error(path + ": cannot write (" + reason() + ")");
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const std::string why = n < 0 ? reason() : "nothing written";
      ::close(fd);
      throw Error(path + ": write failed after " + std::to_string(done) + " of " + std::to_string(bytes.size()) +
                  " bytes (" + why + ")");
    }
    done += static_cast<std::size_t>(n);
  }
  if (::close(fd) != 0) throw Error(path + ": write failed at close (" + reason() + ")");
  f.commit();
}

}  // namespace impinge
