#pragma once
/// @file atomic_file.hpp
/// Files written whole or not at all: every output of impinge (CSV, JSON, PLY, VTP, PVD, PNG, map files)
/// is written to a temporary file in its own folder and renamed over its name only once every write and
/// the close have succeeded (POSIX rename(2) replaces the name in one step). A run killed mid-write, or
/// a full disk, leaves the previous file or none, never a truncated one; rename replaces a symbolic link
/// at the name itself, so no file outside the folder is ever written through one.

#include <string>
#include <string_view>

namespace impinge {

/// A temporary file beside `path` (same folder: "<name>.tmp-<pid>-<n>", created exclusively, mode 0644
/// less the umask) for a writer that needs a file name (libpng, a binary stream): write to temp_path(),
/// then commit(). Removed by the destructor unless committed.
class AtomicFile {
 public:
  /// Throws impinge::Error naming `path` when its folder does not exist or the temporary file cannot be
  /// created (with the system's reason).
  explicit AtomicFile(std::string path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  const std::string& path() const { return path_; }
  const std::string& temp_path() const { return temp_; }
  /// Rename the temporary file over path(). Throws impinge::Error naming path() on failure (the
  /// temporary file is then removed).
  void commit();

 private:
  std::string path_, temp_;
  bool committed_ = false;
};

/// Write `bytes` to `path` atomically (AtomicFile): every write(2) checked, the file closed and checked,
/// then renamed. Throws impinge::Error naming `path` and the system's reason ("No space left on device",
/// "File too large") on any failure; `path` then keeps its previous content, or does not exist.
void write_file_atomically(const std::string& path, std::string_view bytes);

}  // namespace impinge
