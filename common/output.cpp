#include "common/output.hpp"

#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <set>

#include "common/errors.hpp"
#include "common/version.hpp"

namespace swim::output {

namespace fs = std::filesystem;

void make_dir(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw InputError("--out", "\"" + dir + "\"", "cannot create the output directory: " + ec.message());
}

std::string first_non_finite(const json& v, const std::string& at) {
  if (v.is_number_float()) return std::isfinite(v.get<double>()) ? std::string() : (at.empty() ? "(top)" : at);
  if (v.is_object()) {
    for (const auto& [k, e] : v.items())
      if (std::string p = first_non_finite(e, at.empty() ? k : at + "." + k); !p.empty()) return p;
  } else if (v.is_array()) {
    for (std::size_t i = 0; i < v.size(); ++i)
      if (std::string p = first_non_finite(v[i], at + "[" + std::to_string(i) + "]"); !p.empty()) return p;
  }
  return {};
}

bool all_finite(const json& v) { return first_non_finite(v).empty(); }

void write_json(const std::string& path, const json& value) {
  if (const std::string at = first_non_finite(value); !at.empty())
    throw NumericalError("a non-finite number reached " + path + " (at " + at + ")",
                         "report this scene; the solver should have stopped earlier");
  const fs::path p(path);
  const bool summary = p.filename() == "summary.json";
  const json* out = &value;
  json with_files;
  if (summary) {
    const std::string dir = p.parent_path().string();
    // the commit point of the run: never after a failed file
    if (const Failure f = first_failure(dir); !f.file.empty()) throw OutputError(f.file, f.reason);
    with_files = value;
    json files = json::array();
    for (const auto& r : committed_files(dir))
      if (r.name != "summary.json" && fs::path(r.name).filename().string()[0] != '.') files.push_back({{"name", r.name}, {"bytes", r.bytes}, {"fnv1a64", r.fnv1a64}});
    with_files["files"] = files;
    with_files["swim_version"] = version();
    out = &with_files;
  }
  AtomicFile f(path);
  if (carries_own_checksum(path)) f.stream() << json_text_with_checksum(*out);
  else f.stream() << out->dump(2, ' ', false, json::error_handler_t::replace) << "\n";
  f.commit();
}

void adopt_listed(const std::string& dir) {
  const fs::path d(dir);
  std::ifstream in(d / "summary.json");
  const json s = json::parse(in, nullptr, false);
  if (s.is_discarded() || !s.is_object()) return;
  std::set<std::string> have;
  for (const auto& r : committed_files(dir)) have.insert(r.name);
  if (!have.count("summary.json")) adopt((d / "summary.json").string());
  if (!s.contains("files") || !s["files"].is_array()) return;
  for (const auto& f : s["files"])
    if (f.contains("name") && f["name"].is_string() && !have.count(f["name"].get<std::string>()))
      adopt((d / f["name"].get<std::string>()).string());
}

bool amend_summary(const std::string& dir, const std::function<void(json&)>& change) {
  const std::string path = (fs::path(dir) / "summary.json").string();
  std::ifstream in(path);
  json j = json::parse(in, nullptr, false);
  if (j.is_discarded() || !j.is_object()) return false;
  adopt_listed(dir);
  for (const char* k : {"files", "swim_version", "checksum_algorithm", "self_fnv1a64"}) j.erase(k);
  change(j);
  write_json(path, j);
  return true;
}

bool carries_own_checksum(const std::string& path) {
  const std::string name = fs::path(path).filename().string();
  return name == "summary.json" || name == "calibration.json";
}

namespace {
constexpr std::string_view kOwnKey = "\"self_fnv1a64\": \"";
constexpr std::string_view kZeros = "0000000000000000";
}  // namespace

std::string json_text_with_checksum(json value) {
  value.erase("checksum_algorithm");
  value.erase("self_fnv1a64");
  value["checksum_algorithm"] = kChecksumAlgorithm;
  value["self_fnv1a64"] = std::string(kZeros);
  std::string text = value.dump(2, ' ', false, json::error_handler_t::replace) + "\n";
  // the key is the text's last: its value is found from the end, never inside a scene's text
  const std::size_t at = text.rfind(kOwnKey);
  const std::string sum = hex64(fnv1a64(text));
  text.replace(at + kOwnKey.size(), kZeros.size(), sum);
  return text;
}

OwnChecksum check_own_checksum(std::string_view text) {
  const std::size_t at = text.rfind(kOwnKey);
  if (at == std::string_view::npos) {
    // a file of an older swim is complete JSON without the trailer; a cut one is not JSON
    const json j = json::parse(text, nullptr, false);
    return !j.is_discarded() && j.is_object() && !j.contains("checksum_algorithm") ? OwnChecksum::Absent
                                                                                   : OwnChecksum::Mismatch;
  }
  const std::size_t v = at + kOwnKey.size();
  if (text.size() < v + kZeros.size() + 1 || text[v + kZeros.size()] != '"') return OwnChecksum::Mismatch;
  const std::string_view written = text.substr(v, kZeros.size());
  if (written.find_first_not_of("0123456789abcdef") != std::string_view::npos) return OwnChecksum::Mismatch;
  std::string zeroed(text);
  zeroed.replace(v, kZeros.size(), kZeros);
  return hex64(fnv1a64(zeroed)) == written ? OwnChecksum::Ok : OwnChecksum::Mismatch;
}

CsvWriter::CsvWriter(const std::string& path, std::vector<std::string> header)
    : out_(std::make_unique<AtomicFile>(path)), header_(std::move(header)), path_(path),
      exceptions_at_start_(std::uncaught_exceptions()) {
  auto& o = out_->stream();
  for (size_t i = 0; i < header_.size(); ++i) o << (i ? "," : "") << header_[i];
  o << "\n";
}

CsvWriter::~CsvWriter() {
  // Closed by scope: publish unless an exception is unwinding through the writer (then
  // the file is partial and stays unpublished). A failure cannot be thrown from here; the
  // ledger keeps it and the folder's summary.json is refused.
  if (out_->committed() || std::uncaught_exceptions() > exceptions_at_start_) return;
  try {
    out_->commit();
  } catch (const std::exception&) {
  }
}

void CsvWriter::close() { out_->commit(); }

void CsvWriter::row(const std::vector<double>& values) {
  if (values.size() != header_.size()) throw std::logic_error("CSV row width mismatch in " + path_);
  char b[40];
  auto& o = out_->stream();
  for (size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i]))
      throw NumericalError("non-finite value in column '" + header_[i] + "' of " + path_,
                           "tighten the solver tolerances or reduce the time step");
    o << (i ? "," : "") << csv_number(values[i], b);
  }
  o << "\n";
}

}  // namespace swim::output
