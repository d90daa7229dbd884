// Atomic, checked result files. Every result file of a run is written to a temporary name
// in its own folder (".<name>.tmp-<pid>"), its stream state and close are checked, and only
// then is it renamed over the final name: a reader never sees a half-written file under a
// result name, and a failed write never leaves one.
//
// Any failure (disk full, read-only folder, a directory where the file should be) is a
// swim::OutputError naming the file ("disk full while writing radius.csv"): exit 3.
//
// Every committed file is recorded (size and FNV-1a 64-bit checksum) in a process-wide
// ledger per folder; writing a folder's summary.json (output::write_json) lists them and
// refuses when a file of that folder failed, so summary.json is always written last and
// never claims success for a folder with a missing or partial file.
//
// Test hook: SWIM_TEST_FAIL_WRITE=<file name>[:<bytes>] makes writes to files of that name
// fail with "No space left on device" after <bytes> bytes (default 0), as on a full disk.
#pragma once

#include <cstdint>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

namespace swim::output {

class AtomicFile {
 public:
  /// Opens the temporary file next to `path`. Throws OutputError when it cannot.
  explicit AtomicFile(std::string path);
  /// Not committed: the temporary file is removed and the final name is left untouched.
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::ostream& stream();
  /// Flush, check, close, rename to the final name, record it. Throws OutputError.
  void commit();
  bool committed() const { return committed_; }
  const std::string& path() const { return path_; }

 private:
  struct Impl;
  std::string path_;
  std::unique_ptr<Impl> impl_;
  bool committed_ = false;
};

/// A committed file: path relative to the folder whose ledger holds it.
struct FileRecord {
  std::string name;
  std::uintmax_t bytes = 0;
  std::string fnv1a64;  ///< 16 hex digits
};

/// Files committed (by this process) into `dir` and its subfolders, in commit order, latest
/// record per name.
std::vector<FileRecord> committed_files(const std::string& dir);
/// A failed write: the file (relative to the folder asked about) and the reason.
struct Failure {
  std::string file, reason;
};
/// The first write failure in `dir` or its subfolders; file empty when none.
Failure first_failure(const std::string& dir);
/// Record a failure (also one that could not be thrown: a writer closed by its destructor).
void note_failure(const std::string& path, const std::string& reason);
/// Forget the ledger of `dir` (a new run owns the folder).
void reset_ledger(const std::string& dir);

/// FNV-1a 64-bit checksum of a file's bytes, as 16 hex digits ("" when unreadable).
std::string file_checksum(const std::string& path);

}  // namespace swim::output
