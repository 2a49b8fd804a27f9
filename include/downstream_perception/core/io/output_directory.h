// Files written on request (a ROS service, a tool) go through one OutputDirectory: only inside
// its configured directory, never through a symlink, never over an existing file unless asked,
// and never half-written. A service's caller may be anyone on the ROS graph, so its request is
// a name, not a path the node's user could be tricked into writing (`../../.bashrc`, a symlink
// planted in the directory, `victim.txt\0.ply`).
#pragma once

#include <cstddef>
#include <string>

namespace downstream_perception {

/// Where a write went, or why it did not.
struct OutputFileResult {
  std::string error;  ///< empty on success; otherwise the reason (never echoes a huge name)
  std::string path;   ///< the absolute path written (on success)
  bool ok() const { return error.empty(); }
};

class OutputDirectory {
 public:
  static constexpr std::size_t kMaxNameBytes = 1024;      ///< the whole relative name
  static constexpr std::size_t kMaxComponentBytes = 255;  ///< one path component (NAME_MAX)

  /// `directory` must be absolute; it is created (with its parents) on the first write.
  explicit OutputDirectory(std::string directory);

  const std::string& directory() const { return directory_; }

  /// The reason `name` cannot be written (empty if it can): a relative path of at most
  /// kMaxNameBytes that stays inside after normalisation (no "..", no absolute path), without
  /// NUL or control characters, ending in `extension` (e.g. ".ply").
  std::string checkName(const std::string& name, const std::string& extension) const;

  /// Writes `content` as `name` (checked by checkName) inside the directory: missing
  /// subdirectories are created; no component may be a symlink (opened with O_NOFOLLOW); an
  /// existing file is kept unless `overwrite` (and never replaced if it is not a regular file);
  /// the bytes go to a temporary file in the same directory that is renamed into place, so a
  /// failure leaves no partial file.
  OutputFileResult write(const std::string& name, const std::string& extension,
                         const std::string& content, bool overwrite) const;

 private:
  std::string directory_;
};

/// At most `max_bytes` of `text` for a message, with "..." and the full length if cut (a 1 MB
/// request is not echoed back whole), control characters shown as '?'.
std::string shortenForMessage(const std::string& text, std::size_t max_bytes = 80);

}  // namespace downstream_perception
