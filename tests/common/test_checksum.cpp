// The product's checksum (common/checksum.hpp) is the standard FNV-1a 64, and the files it
// protects are verified before they are trusted: a summary.json or calibration.json carries a
// checksum of itself, and output::verify_folder finds any changed digit, truncation or deletion
// of a run folder's files (summary.json, series.csv, radius.csv, scene.resolved.json,
// checkpoint.bin) or of a calibration file, naming the file.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "common/atomic_file.hpp"
#include "common/checksum.hpp"
#include "common/output.hpp"
#include "common/run_folder.hpp"
#include "common/run_record.hpp"

namespace fs = std::filesystem;
using namespace swim;

namespace {

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}
void spit(const fs::path& p, const std::string& s) { std::ofstream(p, std::ios::binary) << s; }

struct Scratch {
  fs::path root = fs::temp_directory_path() / ("swim_checksum_" + std::to_string(::getpid()));
  Scratch() { fs::create_directories(root); }
  ~Scratch() {
    std::error_code ec;
    fs::remove_all(root, ec);
  }
};

/// A small finished run folder as the tiers write it: series.csv, radius.csv, solver_stats.json,
/// scene.resolved.json, a checkpoint.bin, summary.json last listing them.
void write_run_folder(const std::string& dir) {
  fs::create_directories(dir);
  output::reset_ledger(dir);
  record::RunRecord r("1d", "force_free_unbounded", 1e-5, record::common_series_columns(), {0.0, 5e-6, 1e-5});
  for (int k = 0; k <= 20; ++k) {
    std::vector<double> row(r.series.width(), 0.0);
    row[0] = 0.01 * k;
    row[1] = 1e-7 * k;
    row[2] = 1e-5;
    row[3] = 1e-18;
    row[4] = 0.9e-6;
    row[5] = 1.1e-6;
    r.add_row(row);
    const std::vector<double> radius = {1e-6, 0.95e-6 + 1e-9 * k, 1e-6};
    r.add_radius(0.01 * k, radius);
  }
  {
    output::AtomicFile ck(dir + "/checkpoint.bin");
    ck.stream() << std::string(300, 'c') << "state 12345";
    ck.commit();
  }
  record::write_run(dir, r, {{"name", "trusted"}, {"swimmer", {{"radius", "1 um"}}}});
}

/// One kind of damage to one file.
struct Damage {
  const char* name;
  std::function<void(const fs::path&)> apply;
};

const std::vector<Damage>& damages() {
  static const std::vector<Damage> d = {
      {"a changed digit",
       [](const fs::path& p) {
         std::string s = slurp(p);
         const std::size_t at = s.find_last_of("123456789");
         ASSERT_NE(at, std::string::npos) << p;
         s[at] = s[at] == '9' ? '8' : char(s[at] + 1);
         spit(p, s);
       }},
      {"truncation",
       [](const fs::path& p) {
         const std::string s = slurp(p);
         spit(p, s.substr(0, s.size() * 2 / 3));
       }},
      {"deletion", [](const fs::path& p) { fs::remove(p); }},
  };
  return d;
}

}  // namespace

TEST(Checksum, Fnv1a64IsTheStandardOneWithItsPublishedTestVectors) {
  EXPECT_EQ(kFnv1a64Offset, 14695981039346656037ull);
  EXPECT_EQ(kFnv1a64Prime, 1099511628211ull);
  // IETF draft-eastlake-fnv and Noll's FNV page
  EXPECT_EQ(hex64(fnv1a64(std::string(""))), "cbf29ce484222325");
  EXPECT_EQ(hex64(fnv1a64(std::string("a"))), "af63dc4c8601ec8c");
  EXPECT_EQ(hex64(fnv1a64(std::string("foobar"))), "85944171f73967e8");
  // streamed in pieces as the file writers do
  const std::string text = "foobar";
  EXPECT_EQ(fnv1a64(text.data() + 3, 3, fnv1a64(text.data(), 3)), fnv1a64(text));
  // a file's checksum is the one any FNV-1a 64 tool gives for its bytes
  Scratch s;
  spit(s.root / "f.txt", "foobar");
  EXPECT_EQ(output::file_checksum((s.root / "f.txt").string()), "85944171f73967e8");
  // the legacy basis is one digit short and gives other values
  EXPECT_NE(fnv1a64("a", 1, kFnv1a64LegacyOffset), fnv1a64(std::string("a")));
}

TEST(Checksum, SummaryAndCalibrationFilesCarryTheirOwnChecksumAndNameTheAlgorithm) {
  Scratch s;
  const fs::path cal = s.root / "calibration.json";
  output::write_json(cal.string(), {{"C1_Pa_per_m", 123.456}, {"status", "ok"}});
  const std::string text = slurp(cal);
  EXPECT_EQ(output::check_own_checksum(text), output::OwnChecksum::Ok);
  const auto j = output::json::parse(text);
  EXPECT_EQ(j["checksum_algorithm"], kChecksumAlgorithm);
  ASSERT_TRUE(j["self_fnv1a64"].is_string());
  // the checksum is FNV-1a 64 of the text with its own 16 digits as zeros: verifiable by any tool
  std::string zeroed = text;
  zeroed.replace(zeroed.rfind(j["self_fnv1a64"].get<std::string>()), 16, std::string(16, '0'));
  EXPECT_EQ(hex64(fnv1a64(zeroed)), j["self_fnv1a64"].get<std::string>());
  // a changed digit anywhere is found
  std::string changed = text;
  changed[changed.find("123.456") + 2] = '4';
  EXPECT_EQ(output::check_own_checksum(changed), output::OwnChecksum::Mismatch);
  EXPECT_EQ(output::check_own_checksum(text.substr(0, text.size() - 30)), output::OwnChecksum::Mismatch);
  // a file written before files carried their own checksum is recognised as such
  EXPECT_EQ(output::check_own_checksum("{\"C1_Pa_per_m\": 1.0}"), output::OwnChecksum::Absent);
  // other JSON files (a resolved scene, solver statistics) are written as they are
  output::write_json((s.root / "scene.resolved.json").string(), {{"name", "x"}});
  EXPECT_EQ(output::json::parse(slurp(s.root / "scene.resolved.json")), output::json({{"name", "x"}}));
}

TEST(VerifyFolder, EveryDamageOfEveryFileIsFoundNamingTheFile) {
  Scratch s;
  const std::string clean = (s.root / "clean").string();
  write_run_folder(clean);
  const std::vector<std::string> required = {"series.csv", "radius.csv", "scene.resolved.json"};
  ASSERT_EQ(output::verify_folder(clean, required), "");
  const auto summary = output::json::parse(slurp(fs::path(clean) / "summary.json"));
  EXPECT_EQ(summary["checksum_algorithm"], kChecksumAlgorithm);
  int cases = 0;
  for (const std::string file : {"summary.json", "series.csv", "radius.csv", "scene.resolved.json", "checkpoint.bin"})
    for (const Damage& d : damages()) {
      const fs::path dir = s.root / ("damaged-" + std::to_string(cases++));
      fs::copy(clean, dir, fs::copy_options::recursive);
      ASSERT_EQ(output::verify_folder(dir.string(), required), "");
      d.apply(dir / file);
      const std::string why = output::verify_folder(dir.string(), required);
      EXPECT_EQ(why.rfind(file + ":", 0), 0u) << file << ", " << d.name << ": " << why;
      if (d.name == std::string("deletion")) {
        EXPECT_NE(why.find("missing"), std::string::npos) << why;
      }
    }
  // a file the reader needs that the summary does not list (a summary marked failed lists none)
  output::json j = output::json::parse(slurp(fs::path(clean) / "summary.json"));
  j.erase("files");
  spit(fs::path(clean) / "summary.json", output::json_text_with_checksum(j));
  EXPECT_EQ(output::verify_folder(clean, required), "series.csv: not listed in summary.json");
  // a folder of an older swim: no checksum of its own, checksums with the legacy basis
  j.erase("checksum_algorithm");
  j.erase("self_fnv1a64");
  spit(fs::path(clean) / "summary.json", j.dump(2));
  EXPECT_NE(output::verify_folder(clean, required).find("written by an older swim"), std::string::npos);
}

TEST(VerifyFolder, EveryDamageOfACalibrationFileIsFound) {
  Scratch s;
  const fs::path clean = s.root / "cal";
  fs::create_directories(clean);
  output::write_json((clean / "calibration.json").string(),
                     {{"C1_Pa_per_m", 5.25e6}, {"hydraulic_offset_inner_m", 1.5e-8}, {"status", "ok"}});
  ASSERT_EQ(output::verify_folder(clean.string(), {}, "calibration.json"), "");
  int cases = 0;
  for (const Damage& d : damages()) {
    const fs::path dir = s.root / ("cal-" + std::to_string(cases++));
    fs::copy(clean, dir, fs::copy_options::recursive);
    d.apply(dir / "calibration.json");
    const std::string why = output::verify_folder(dir.string(), {}, "calibration.json");
    EXPECT_EQ(why.rfind("calibration.json:", 0), 0u) << d.name << ": " << why;
  }
}
