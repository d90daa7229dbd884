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

#include "common/checksum.hpp"

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

/// A streamed result file (series.csv, radius.csv): written under the visible partial name
/// "<name>.part" while the run produces it, and renamed to its name by commit(), after the
/// stream state and the close are checked. While the run goes on, sync() flushes and checks
/// the file and records the part file, with its size and checksum so far, in the folder's
/// ledger (a summary.json written then lists it: the rows up to that size are valid). An
/// abandoned part file is kept: its rows are partial results.
///
/// A resumed run continues a part file from a mark (the size and checksum recorded by a
/// checkpoint): the bytes up to the mark must match, and what follows them (written after the
/// checkpoint by the interrupted process) is cut off. A run that ended in failure (at its time
/// limit, say) published its part file under the final name; that file is continued then.
class PartFile {
 public:
  struct Mark {
    std::uintmax_t bytes = 0;
    std::uint64_t checksum = kFnv1a64Offset;
  };
  /// A fresh part file (an old one is truncated). Throws OutputError.
  explicit PartFile(std::string path);
  /// Continue from `from`. Throws InputError (key "--resume") when the part file is missing
  /// or its first from.bytes bytes do not have the checksum; OutputError when it cannot be
  /// opened for writing.
  PartFile(std::string path, Mark from);
  ~PartFile();
  PartFile(const PartFile&) = delete;
  PartFile& operator=(const PartFile&) = delete;

  std::ostream& stream();
  /// The file's size so far (written and buffered).
  std::uintmax_t bytes() const;
  /// Flush and check; record the part file in the ledger. Returns the mark of the bytes on
  /// disk. Throws OutputError.
  Mark sync();
  /// Flush, check, close, rename "<name>.part" to "<name>", record it. Throws OutputError.
  void commit();
  bool committed() const { return committed_; }
  const std::string& path() const { return path_; }
  std::string part_path() const { return path_ + ".part"; }
  /// True when the part file of `path` (or, without one, `path` itself) exists and its first
  /// from.bytes bytes have the checksum.
  static bool matches(const std::string& path, Mark from);

 private:
  void open(int flags, Mark from);
  std::string path_;
  struct Impl;
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

/// Record a file already in its folder in the ledger, with its size and checksum now: a file
/// an earlier process of the same run committed (the VTK frames a resumed run wrote before its
/// checkpoint), so that the folder's summary.json lists it. False when it is not a readable
/// regular file.
bool adopt(const std::string& path);

/// FNV-1a 64-bit checksum of a file's bytes, as 16 hex digits ("" when unreadable).
std::string file_checksum(const std::string& path);

}  // namespace swim::output
