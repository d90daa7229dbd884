// Output writers shared by both tiers: summary.json, series CSV files, solver statistics.
// No writer ever emits NaN or Inf: a non-finite value is a numerical failure (exit 3).
//
// Every file goes through output::AtomicFile (common/atomic_file.hpp): written to a
// temporary name, checked, renamed. A write failure is a swim::OutputError (exit 3) naming
// the file. Writing a folder's summary.json is the run's commit point: it is refused when
// any file of the folder failed, and it lists every file written with its size and checksum
// ("files").
#pragma once

#include <charconv>
#include <functional>
#include <initializer_list>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "common/atomic_file.hpp"

namespace swim::output {

/// v with 10 significant digits, as printf("%.10g") writes it (the CSV files' number format),
/// into b; returns the characters written. std::to_chars: several times faster than printf.
inline std::string_view csv_number(double v, char (&b)[40]) {
  const auto r = std::to_chars(b, b + sizeof b, v, std::chars_format::general, 10);
  return {b, std::size_t(r.ptr - b)};
}

using json = nlohmann::ordered_json;

/// Create `dir` (and parents). Throws InputError (key "--out") when it cannot be created.
void make_dir(const std::string& dir);

/// Write `value` as indented JSON to `path`, atomically; every number must be finite.
/// For a file named summary.json, a "files" list (name, bytes, fnv1a64) of the files
/// written into its folder is added, and a folder with a failed file is an OutputError.
/// summary.json and calibration.json also carry a checksum of themselves (json_text_with_checksum).
void write_json(const std::string& path, const json& value);

/// Record in the ledger the files of a finished run folder that an earlier process committed:
/// its summary.json and every file the summary's "files" names, except those this process has
/// committed itself; a file no longer readable is left out. So a summary written into a
/// folder holding `dir` (or into `dir` itself) lists them.
void adopt_listed(const std::string& dir);

/// `dir`/summary.json committed again (still last, its "files" and checksums renewed) after
/// `change` edited it; the files it listed that an earlier process committed stay listed
/// (adopt_listed). False, nothing written, when there is no readable summary.json.
bool amend_summary(const std::string& dir, const std::function<void(json&)>& change);

/// True for the files that carry a checksum of themselves: summary.json and calibration.json,
/// the commit points of run and calibration folders.
bool carries_own_checksum(const std::string& path);

/// `value` as indented JSON text ending with "checksum_algorithm" (kChecksumAlgorithm) and
/// "self_fnv1a64": the FNV-1a 64 of the whole text with those 16 digits written as zeros. Any
/// "checksum_algorithm" and "self_fnv1a64" already in `value` are replaced.
std::string json_text_with_checksum(json value);

/// What a JSON text's own checksum says of it.
enum class OwnChecksum {
  Ok,        ///< "self_fnv1a64" matches the text
  Absent,    ///< complete JSON without "checksum_algorithm" and "self_fnv1a64": written before
             ///< files carried them (with the legacy basis)
  Mismatch,  ///< the text was changed or cut after it was written (or its checksum is malformed)
};
OwnChecksum check_own_checksum(std::string_view text);

/// True when `value` holds no NaN/Inf number anywhere.
bool all_finite(const json& value);
/// The path of the first non-finite number in `value` ("cases[3].models1d[0].x_m"), empty
/// when every number is finite; `at` prefixes the path.
std::string first_non_finite(const json& value, const std::string& at = "");

/// A CSV file with a fixed header; rows of doubles written with 10 significant digits.
/// The file appears under its name at close() (or when the writer goes out of scope
/// normally; a failure there is recorded and refuses the folder's summary.json).
class CsvWriter {
 public:
  CsvWriter(const std::string& path, std::vector<std::string> header);
  ~CsvWriter();
  /// Throws swim::NumericalError naming the column when a value is not finite.
  void row(const std::vector<double>& values);
  void flush() { out_->stream().flush(); }
  /// Check and publish the file; throws OutputError.
  void close();

 private:
  std::unique_ptr<AtomicFile> out_;
  std::vector<std::string> header_;
  std::string path_;
  int exceptions_at_start_ = 0;
};

}  // namespace swim::output
