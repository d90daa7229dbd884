#include "reduced1d/recorded_wave.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string_view>
#include <system_error>

#include "common/errors.hpp"
#include "common/scene_shared.hpp"

namespace swim::reduced1d {

double RecordedRadius::min_radius() const { return *std::min_element(R.begin(), R.end()); }
double RecordedRadius::max_radius() const { return *std::max_element(R.begin(), R.end()); }

namespace {

bool parse_number(std::string_view s, double& v) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  if (s.empty()) return false;
  if (s.front() == '+') s.remove_prefix(1);
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size() && std::isfinite(v);
}

std::string fmt_m(double v) { return scene::format_quantity(v, "m"); }

}  // namespace

std::shared_ptr<const RecordedRadius> read_radius_file(const std::string& key, const std::string& path,
                                                       const std::string& scene_dir, double L) {
  namespace fs = std::filesystem;
  const std::string shown = "\"" + path + "\"";
  auto bad = [&](const std::string& what) { return InputError(key, shown, what); };
  if (path.empty()) throw bad("a radius.csv (t_s, z_m, radius_m) written by swim run; the path is empty");
  fs::path p(path);
  std::error_code ec;
  if (p.is_relative() && !fs::exists(p, ec)) p = fs::path(scene_dir) / path;
  if (fs::exists(p, ec) && !fs::is_regular_file(p, ec))
    throw bad("a radius.csv (t_s, z_m, radius_m) written by swim run; this is a directory or another kind of file");
  std::ifstream in(p, std::ios::binary);
  if (!in)
    throw bad("radius file not found or not readable (a radius.csv written by swim run; relative paths are tried "
              "from the working directory, then from the scene's directory)");
  std::string line;
  if (!std::getline(in, line)) throw bad("the radius file is empty; its first line must be the header t_s,z_m,radius_m");
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (line != "t_s,z_m,radius_m")
    throw bad("the first line must be the header t_s,z_m,radius_m (the long format of radius.csv, docs/outputs.md); "
              "it is \"" + line.substr(0, 80) + "\"");
  auto rec = std::make_shared<RecordedRadius>();
  std::vector<double> zrow;
  long row = 1;
  double t_cur = 0;
  bool have_time = false;
  auto close_time = [&]() {
    if (rec->t.size() == 1) {
      rec->z = zrow;
      if (rec->z.size() < 2) throw bad("every time of the record must hold at least 2 rings; the first holds " +
                                       std::to_string(rec->z.size()));
    } else if (zrow.size() != rec->z.size()) {
      throw bad("every time of the record must hold the same rings: the first time holds " +
                std::to_string(rec->z.size()) + ", t = " + scene::format_quantity(t_cur, "s") + " holds " +
                std::to_string(zrow.size()));
    } else {
      for (std::size_t j = 0; j < zrow.size(); ++j)
        if (!(std::abs(zrow[j] - rec->z[j]) <= 1e-9 * L))
          throw bad("every time of the record must hold the same rings: at t = " + scene::format_quantity(t_cur, "s") +
                    " ring " + std::to_string(j) + " is at z = " + fmt_m(zrow[j]) + ", at the first time at " +
                    fmt_m(rec->z[j]));
    }
  };
  while (std::getline(in, line)) {
    ++row;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    double v[3];
    std::string_view s(line);
    int c = 0;
    bool ok = true;
    for (; c < 3 && ok; ++c) {
      const std::size_t comma = s.find(',');
      const std::string_view cell = c < 2 ? s.substr(0, comma) : s;
      if (c < 2 && comma == std::string_view::npos) ok = false;
      else ok = parse_number(cell, v[c]);
      if (c < 2 && ok) s.remove_prefix(comma + 1);
    }
    if (!ok)
      throw bad("line " + std::to_string(row) + " must be three finite numbers t_s,z_m,radius_m; it is \"" +
                line.substr(0, 80) + "\"");
    if (!(v[2] > 0)) throw bad("line " + std::to_string(row) + ": the radius must be positive; it is " + fmt_m(v[2]));
    if (!have_time || v[0] != t_cur) {
      if (have_time && !(v[0] > t_cur))
        throw bad("the times must increase (rows grouped by time, as radius.csv writes them): line " +
                  std::to_string(row) + " has t = " + scene::format_quantity(v[0], "s") + " after t = " +
                  scene::format_quantity(t_cur, "s"));
      if (have_time) close_time();
      rec->t.push_back(v[0]);
      t_cur = v[0];
      have_time = true;
      zrow.clear();
    }
    if (!zrow.empty() && !(v[1] > zrow.back()))
      throw bad("line " + std::to_string(row) + ": the rings' z_m must increase within each time; z = " + fmt_m(v[1]) +
                " follows " + fmt_m(zrow.back()));
    zrow.push_back(v[1]);
    rec->R.push_back(v[2]);
  }
  if (in.bad()) throw bad("the radius file could not be read to its end");
  if (!have_time) throw bad("the radius file holds no rows; a recorded wave needs at least 2 times");
  close_time();
  if (rec->t.size() < 2)
    throw bad("a recorded wave needs at least 2 times; the file holds 1 (t = " +
              scene::format_quantity(rec->t[0], "s") + ")");
  // the rings must cover the tube [0, L] (swimmer.length): each end within half a ring spacing
  // (a 1D record's cell centres lie half a cell in) plus 2 % of L, and no ring further than 2 % of
  // L outside
  const std::size_t m = rec->z.size();
  const double tol = 0.02 * L;
  const double gap0 = 0.5 * (rec->z[1] - rec->z[0]) + tol, gapL = 0.5 * (rec->z[m - 1] - rec->z[m - 2]) + tol;
  if (!(rec->z.front() >= -tol && rec->z.front() <= gap0 && rec->z.back() <= L + tol && rec->z.back() >= L - gapL))
    throw bad("the rings' z span [" + fmt_m(rec->z.front()) + ", " + fmt_m(rec->z.back()) +
              "] must cover the tube [0, swimmer.length = " + fmt_m(L) +
              "] to within half a ring spacing plus 2 % of the length at each end (record a run of a tube of the "
              "scene's length)");
  // times from 0
  const double t0 = rec->t.front();
  for (double& x : rec->t) x -= t0;
  for (std::size_t k = 0; k + 1 < rec->t.size(); ++k)
    if (!(rec->t[k + 1] > rec->t[k]))
      throw bad("the times must increase strictly; two times coincide after shifting the record to start at 0");
  return rec;
}

}  // namespace swim::reduced1d
