/// @file
/// The lock of an output folder: one run at a time writes into a --out DIR, so that nothing
/// a run leaves (results, summary, frames) mixes two runs.
#pragma once

#include <filesystem>
#include <string>

#include "core/errors.hpp"

namespace flexmbd {

/// The lock file's name in the output folder.
constexpr const char* kOutputLockName = ".flexmbd.lock";

/// DIR/.flexmbd.lock, held (flock) for the life of this object and holding the process id
/// of the run, removed when the object goes. A lock left by a run that was killed is not
/// held by any process: it is stale and taken over.
class OutputLock {
 public:
  /// Creates `dir` (and parents) and takes its lock. `option` names the folder in messages
  /// ("--out").
  /// @throws InputError (exit 2) if `dir` exists and is not a folder, another run holds it
  ///         (naming its process id and the lock file), or the folder cannot be created
  ///         or written (with the reason).
  explicit OutputLock(const std::filesystem::path& dir, const std::string& option = "--out");
  ~OutputLock();
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;

 private:
  std::filesystem::path path_;
  int fd_ = -1;
};

}  // namespace flexmbd
