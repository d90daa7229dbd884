// Output writers shared by both tiers: summary.json, series CSV files, solver statistics.
// No writer ever emits NaN or Inf: a non-finite value is a numerical failure (exit 3).
#pragma once

#include <fstream>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace swim::output {

using json = nlohmann::ordered_json;

/// Create `dir` (and parents). Throws InputError (key "--out") when it cannot be created.
void make_dir(const std::string& dir);

/// Write `value` as indented JSON to `path`; every number must be finite.
void write_json(const std::string& path, const json& value);

/// True when `value` holds no NaN/Inf number anywhere.
bool all_finite(const json& value);

/// A CSV file with a fixed header; rows of doubles written with 10 significant digits.
class CsvWriter {
 public:
  CsvWriter(const std::string& path, std::vector<std::string> header);
  /// Throws swim::NumericalError naming the column when a value is not finite.
  void row(const std::vector<double>& values);
  void flush() { out_.flush(); }

 private:
  std::ofstream out_;
  std::vector<std::string> header_;
  std::string path_;
};

}  // namespace swim::output
