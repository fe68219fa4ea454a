#pragma once
// Atomic file output: the bytes go to a hidden temporary beside the destination, flushed to disk,
// and replace the destination only on commit(). A failed or interrupted run never leaves a
// truncated file behind or clobbers an existing one.

#include <filesystem>
#include <string_view>

namespace gilt::raytrace_core::util {

/// Bytes staged in a hidden temporary beside `destination` (same folder, same extension). The
/// destination is untouched until commit(); an uncommitted temporary is removed on destruction.
/// Throws InputError naming the destination when the temporary cannot be written.
class StagedFile {
 public:
  StagedFile(const std::filesystem::path& destination, std::string_view bytes);
  StagedFile(const StagedFile&) = delete;
  StagedFile& operator=(const StagedFile&) = delete;
  ~StagedFile();

  /// Renames the temporary over the destination; throws InputError (and removes it) on failure.
  void commit();

 private:
  [[noreturn]] void fail(int error, bool remove_temporary);
  std::filesystem::path destination_, temporary_;
};

}  // namespace gilt::raytrace_core::util
