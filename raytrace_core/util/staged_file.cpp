// Atomic file output through a temporary file and rename (POSIX: open O_EXCL, write, fsync,
// rename(2) within one folder).

#include "raytrace_core/util/staged_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <string>
#include <system_error>

#include "raytrace_core/util/error.h"

namespace gilt::raytrace_core::util {
namespace fs = std::filesystem;
namespace {

/// Hidden sibling of `destination` that keeps its extension, unique within this machine.
fs::path temporary_path_for(const fs::path& destination) {
  static std::atomic<uint64_t> counter{0};
  // Built by appending: GCC 12 at -O3 warns falsely (-Wrestrict) on a chain of string '+'.
  std::string name = ".";
  name += destination.filename().string();
  name += ".tmp-";
  name += std::to_string(::getpid());
  name += '-';
  name += std::to_string(counter++);
  name += destination.extension().string();
  return destination.parent_path() / name;
}

}  // namespace

StagedFile::StagedFile(const fs::path& destination, std::string_view bytes)
    : destination_(destination), temporary_(temporary_path_for(destination)) {
  const int fd = ::open(temporary_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) fail(errno, false);
  size_t written = 0;
  int error = 0;
  while (written < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + written, bytes.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      error = n < 0 ? errno : EIO;
      break;
    }
    written += static_cast<size_t>(n);
  }
  if (error == 0 && ::fsync(fd) != 0) error = errno;
  if (::close(fd) != 0 && error == 0) error = errno;
  if (error != 0) fail(error, true);
}

StagedFile::~StagedFile() {
  std::error_code ec;
  if (!temporary_.empty()) fs::remove(temporary_, ec);
}

void StagedFile::commit() {
  std::error_code ec;
  fs::rename(temporary_, destination_, ec);
  if (ec) fail(ec.value(), true);
  temporary_.clear();
}

void StagedFile::fail(int error, bool remove_temporary) {
  if (remove_temporary) ::unlink(temporary_.c_str());
  temporary_.clear();
  throw InputError("cannot write '" + destination_.string() + "': " + std::generic_category().message(error));
}

}  // namespace gilt::raytrace_core::util
