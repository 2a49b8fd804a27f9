#include "downstream_perception/core/io/output_directory.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <system_error>
#include <utility>
#include <vector>

namespace downstream_perception {

namespace {

/// A file descriptor closed on scope exit.
class Fd {
 public:
  explicit Fd(int fd = -1) : fd_(fd) {}
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  Fd(Fd&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}
  Fd& operator=(Fd&& other) noexcept {
    std::swap(fd_, other.fd_);
    return *this;
  }
  int get() const { return fd_; }
  bool valid() const { return fd_ >= 0; }
  /// Hands the descriptor over (to close it and see the result).
  int release() { return std::exchange(fd_, -1); }

 private:
  int fd_;
};

std::string errnoText(const std::string& what) {
  return what + ": " + std::strerror(errno);
}

/// The components of a checked relative name ("." and empty ones dropped).
std::vector<std::string> components(const std::string& name) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start <= name.size()) {
    const std::size_t end = std::min(name.find('/', start), name.size());
    const std::string part = name.substr(start, end - start);
    if (!part.empty() && part != ".") out.push_back(part);
    start = end + 1;
  }
  return out;
}

bool writeAll(int fd, const std::string& content) {
  const char* p = content.data();
  std::size_t left = content.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  return true;
}

}  // namespace

std::string shortenForMessage(const std::string& text, std::size_t max_bytes) {
  std::string out = text.substr(0, max_bytes);
  for (char& c : out) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  }
  if (text.size() > max_bytes) out += "... (" + std::to_string(text.size()) + " bytes)";
  return out;
}

OutputDirectory::OutputDirectory(std::string directory) : directory_(std::move(directory)) {
  while (directory_.size() > 1 && directory_.back() == '/') directory_.pop_back();
}

std::string OutputDirectory::checkName(const std::string& name,
                                       const std::string& extension) const {
  const std::string shown = "'" + shortenForMessage(name) + "'";
  if (name.empty()) return "empty file name";
  if (name.size() > kMaxNameBytes) {
    return "name " + shown + " is longer than " + std::to_string(kMaxNameBytes) + " bytes";
  }
  for (const char c : name) {
    if (c == '\0') return "name " + shown + " contains a NUL byte";
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      return "name " + shown + " contains a control character";
    }
  }
  if (name.front() == '/') {
    return "name " + shown + " is absolute: give a name inside the output directory " + directory_;
  }
  const std::vector<std::string> parts = components(name);
  if (parts.empty()) return "name " + shown + " names no file";
  for (const std::string& part : parts) {
    if (part == "..") return "name " + shown + " leaves the output directory (\"..\")";
    if (part.size() > kMaxComponentBytes) {
      return "a component of " + shown + " is longer than " + std::to_string(kMaxComponentBytes) +
             " bytes";
    }
  }
  const std::string& leaf = parts.back();
  if (leaf.size() <= extension.size() ||
      leaf.compare(leaf.size() - extension.size(), extension.size(), extension) != 0) {
    return "only " + extension + " is supported, got " + shown;
  }
  if (name.back() == '/') return "name " + shown + " ends in '/'";
  return {};
}

OutputFileResult OutputDirectory::write(const std::string& name, const std::string& extension,
                                        const std::string& content, bool overwrite) const {
  OutputFileResult result;
  result.error = checkName(name, extension);
  if (!result.ok()) return result;
  if (directory_.empty() || directory_.front() != '/') {
    result.error = "the output directory '" + directory_ + "' is not an absolute path";
    return result;
  }
  std::error_code ec;
  std::filesystem::create_directories(directory_, ec);  // the configured part may use symlinks
  Fd dir(::open(directory_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (!dir.valid()) {
    result.error = errnoText("cannot open the output directory " + directory_);
    return result;
  }
  const std::vector<std::string> parts = components(name);
  std::string relative;
  for (std::size_t k = 0; k + 1 < parts.size(); ++k) {
    relative += parts[k] + "/";
    if (::mkdirat(dir.get(), parts[k].c_str(), 0755) != 0 && errno != EEXIST) {
      result.error = errnoText("cannot create " + directory_ + "/" + relative);
      return result;
    }
    // O_NOFOLLOW: a symlinked subdirectory (to /etc, say) is refused, not entered.
    Fd sub(::openat(dir.get(), parts[k].c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC));
    if (!sub.valid()) {
      result.error = errnoText(directory_ + "/" + relative + " is not a plain directory");
      return result;
    }
    dir = std::move(sub);
  }
  const std::string& leaf = parts.back();
  const std::string target = directory_ + "/" + relative + leaf;
  struct stat existing {};
  if (::fstatat(dir.get(), leaf.c_str(), &existing, AT_SYMLINK_NOFOLLOW) == 0) {
    if (!S_ISREG(existing.st_mode)) {
      result.error = target + " exists and is not a regular file (a symlink?): not replaced";
      return result;
    }
    if (!overwrite) {
      result.error = target + " exists: kept (ask to overwrite to replace it)";
      return result;
    }
  }
  static std::atomic<unsigned> counter{0};
  const std::string temporary = "." + leaf.substr(0, 200) + ".tmp-" + std::to_string(::getpid()) +
                                "-" + std::to_string(counter++);
  Fd out(::openat(dir.get(), temporary.c_str(),
                  O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644));
  if (!out.valid()) {
    result.error = errnoText("cannot create a temporary file in " + directory_ + "/" + relative);
    return result;
  }
  const bool written = writeAll(out.get(), content) && ::fsync(out.get()) == 0;
  const int close_status = ::close(out.release());  // a failed close may mean lost data
  if (!written || close_status != 0) {
    result.error = errnoText("writing " + target + " failed");
    ::unlinkat(dir.get(), temporary.c_str(), 0);
    return result;
  }
  // Without overwrite, link() refuses an existing name atomically (a file created meanwhile is
  // kept); with it, rename() replaces the name (a symlink there would be replaced, not followed).
  const int placed = overwrite ? ::renameat(dir.get(), temporary.c_str(), dir.get(), leaf.c_str())
                               : ::linkat(dir.get(), temporary.c_str(), dir.get(), leaf.c_str(), 0);
  if (placed != 0) {
    result.error = errno == EEXIST ? target + " exists: kept (ask to overwrite to replace it)"
                                   : errnoText("cannot move the new file to " + target);
    ::unlinkat(dir.get(), temporary.c_str(), 0);
    return result;
  }
  if (!overwrite) ::unlinkat(dir.get(), temporary.c_str(), 0);
  result.path = target;
  return result;
}

}  // namespace downstream_perception
