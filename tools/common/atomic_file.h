#pragma once
// Nothing lost (STYLE.md §7): every output is written to a temporary file beside its final name
// and renamed into place only when complete, so a crash or an error never leaves a partial file.

#include <filesystem>
#include <string>
#include <string_view>

namespace igi {

// A temporary path beside `final_path` (same folder, same extension, so writers that pick the
// format from the extension still work). Commit() renames it onto the final path; if the object
// dies uncommitted, the temporary file is removed.
class AtomicOutput {
 public:
  explicit AtomicOutput(std::filesystem::path final_path);
  ~AtomicOutput();
  AtomicOutput(const AtomicOutput&) = delete;
  AtomicOutput& operator=(const AtomicOutput&) = delete;

  const std::filesystem::path& temp_path() const { return temp_path_; }
  const std::filesystem::path& final_path() const { return final_path_; }
  // Flushes the temporary file to disk and renames it; throws igi::Error on failure.
  void Commit();

 private:
  std::filesystem::path final_path_;
  std::filesystem::path temp_path_;
  bool committed_ = false;
};

// Writes `contents` to `path` atomically (creating parent folders).
void WriteFileAtomic(const std::filesystem::path& path, std::string_view contents);

// Appends one line (a '\n' is added) and flushes it to disk before returning, for append-only
// logs such as manifest.jsonl: a crash loses at most the line being written.
void AppendLineDurable(const std::filesystem::path& path, std::string_view line);

// Reads a whole file; throws InputError "PATH: cannot read: REASON".
std::string ReadFileToString(const std::filesystem::path& path);

}  // namespace igi
