#include "common/output.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "common/errors.hpp"

namespace swim::output {

void make_dir(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw InputError("--out", "\"" + dir + "\"", "cannot create the output directory: " + ec.message());
}

bool all_finite(const json& v) {
  if (v.is_number_float()) return std::isfinite(v.get<double>());
  if (v.is_structured())
    for (const auto& e : v)
      if (!all_finite(e)) return false;
  return true;
}

void write_json(const std::string& path, const json& value) {
  if (!all_finite(value))
    throw NumericalError("a non-finite number reached " + path, "report this scene; the solver should have stopped earlier");
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  out << value.dump(2) << "\n";
}

CsvWriter::CsvWriter(const std::string& path, std::vector<std::string> header)
    : out_(path), header_(std::move(header)), path_(path) {
  if (!out_) throw std::runtime_error("cannot write " + path);
  for (size_t i = 0; i < header_.size(); ++i) out_ << (i ? "," : "") << header_[i];
  out_ << "\n";
}

void CsvWriter::row(const std::vector<double>& values) {
  if (values.size() != header_.size()) throw std::logic_error("CSV row width mismatch in " + path_);
  char b[40];
  for (size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i]))
      throw NumericalError("non-finite value in column '" + header_[i] + "' of " + path_,
                           "tighten the solver tolerances or reduce the time step");
    std::snprintf(b, sizeof b, "%.10g", values[i]);
    out_ << (i ? "," : "") << b;
  }
  out_ << "\n";
}

}  // namespace swim::output
