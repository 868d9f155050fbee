#include "results/output_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

namespace flexmbd {
namespace {

/// The process id written in the lock file at `fd` ("" if none can be read).
std::string holderOf(int fd) {
  char buf[32] = {};
  const ssize_t n = ::pread(fd, buf, sizeof buf - 1, 0);
  std::string s = n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : "";
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  return s;
}

}  // namespace

OutputLock::OutputLock(const std::filesystem::path& dir, const std::string& option) : path_(dir / kOutputLockName) {
  std::error_code ec;
  if (std::filesystem::exists(dir, ec) && !std::filesystem::is_directory(dir, ec)) {
    throw InputError(option + " '" + dir.string() + "' exists and is not a directory");
  }
  std::filesystem::create_directories(dir, ec);
  if (ec) throw InputError("cannot create the output folder " + option + " '" + dir.string() + "': " + ec.message());
  // Open, lock, then check the path still names the file locked: a run ending between
  // the open and the lock removes it, and the next run must not lock a removed file.
  for (int attempt = 0; attempt < 100; ++attempt) {
    const int fd = ::open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) {
      throw InputError("cannot write in the output folder " + option + " '" + dir.string() + "': " +
                       std::strerror(errno) + " (creating its lock file " + kOutputLockName + ")");
    }
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      const int err = errno;
      const std::string holder = holderOf(fd);
      ::close(fd);
      if (err != EWOULDBLOCK) {
        throw InputError("cannot lock the output folder " + option + " '" + dir.string() + "': " + std::strerror(err));
      }
      throw InputError("the output folder " + option + " '" + dir.string() + "' is being written by another run" +
                       (holder.empty() ? "" : " (process " + holder + ")") + ": its lock file " + path_.string() +
                       " is held; wait for that run to end or give another " + option);
    }
    struct stat opened {}, named {};
    if (::fstat(fd, &opened) == 0 && ::stat(path_.c_str(), &named) == 0 && opened.st_ino == named.st_ino &&
        opened.st_dev == named.st_dev) {
      // the process id, for the message of a run refused (a full disk leaves it empty)
      const std::string pid = std::to_string(::getpid()) + "\n";
      if (::ftruncate(fd, 0) == 0 && ::pwrite(fd, pid.data(), pid.size(), 0) < 0) {
      }
      fd_ = fd;
      return;
    }
    ::close(fd);  // removed or replaced meanwhile: again
  }
  throw InputError("cannot lock the output folder " + option + " '" + dir.string() + "': its lock file " +
                   path_.string() + " keeps being replaced");
}

OutputLock::~OutputLock() {
  if (fd_ < 0) return;
  ::unlink(path_.c_str());  // still held: no other run can have taken it
  ::close(fd_);
}

}  // namespace flexmbd
