#include "common/run_folder.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <set>

#include "common/atomic_file.hpp"
#include "common/checksum.hpp"
#include "common/errors.hpp"
#include "common/output.hpp"
#include "common/strict_json.hpp"

namespace swim::output {
namespace fs = std::filesystem;

namespace {

const char* kLock = ".swim.lock";
const char* kOwner = ".swim-run.json";

// At most `limit` bytes of a small file (the lock's PID).
std::string read_text(const fs::path& p, std::size_t limit) {
  std::ifstream in(p, std::ios::binary);
  if (!in) return {};
  std::string s(limit, '\0');
  in.read(s.data(), static_cast<std::streamsize>(limit));
  s.resize(static_cast<std::size_t>(in.gcount()));
  return s;
}

// A JSON file of the folder, or null when absent or unreadable (read to its own size, not
// into a buffer of the size limit: a run folder is opened before every run).
scene::json read_json(const fs::path& p) {
  try {
    std::error_code ec;
    if (!fs::is_regular_file(p, ec)) return nullptr;
    return strict_json::parse_file(p.string(), p.filename().string());
  } catch (const std::exception&) {
    return nullptr;
  }
}

std::string list(const std::vector<std::string>& v, std::size_t max = 5) {
  std::string s;
  for (std::size_t i = 0; i < v.size() && i < max; ++i) s += (i ? ", " : "") + v[i];
  if (v.size() > max) s += ", ... (" + std::to_string(v.size()) + " entries)";
  return s;
}

// The tier of a folder's run: its run record, else its summary; "" when neither says.
std::string tier_in(const scene::json& owner, const scene::json& summary) {
  for (const scene::json* j : {&owner, &summary})
    if (j->is_object() && j->contains("tier") && (*j)["tier"].is_string()) return (*j)["tier"].get<std::string>();
  return "";
}

}  // namespace

std::string RunFolder::tier_of(const std::string& dir) {
  return tier_in(read_json(fs::path(dir) / kOwner), read_json(fs::path(dir) / "summary.json"));
}

std::string json_hash(const scene::json& value) {
  const std::string s = value.dump(-1, ' ', false, scene::json::error_handler_t::replace);
  return hex64(fnv1a64(s));
}

std::string json_hash_legacy(const scene::json& value) {
  const std::string s = value.dump(-1, ' ', false, scene::json::error_handler_t::replace);
  return hex64(fnv1a64(s.data(), s.size(), kFnv1a64LegacyOffset));
}

std::string verify_folder(const std::string& dir, const std::vector<std::string>& required, const std::string& summary) {
  const fs::path sp = fs::path(dir) / summary;
  std::error_code ec;
  if (!fs::is_regular_file(sp, ec)) return summary + ": missing";
  const auto size = fs::file_size(sp, ec);
  if (ec || size > (64u << 20)) return summary + ": unreadable or larger than 64 MB";
  const std::string text = read_text(sp, static_cast<std::size_t>(size));
  switch (check_own_checksum(text)) {
    case OwnChecksum::Ok: break;
    case OwnChecksum::Absent:
      return summary + ": written by an older swim (no checksum of its own; its file checksums use the legacy FNV "
                       "offset basis), so it cannot be verified";
    case OwnChecksum::Mismatch:
      return summary + ": changed or cut after it was written (its own checksum does not match)";
  }
  const scene::json j = scene::json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.is_object()) return summary + ": not valid JSON";
  std::set<std::string> listed;
  if (j.contains("files")) {
    if (!j["files"].is_array()) return summary + ": \"files\" is not a list";
    for (const auto& f : j["files"]) {
      if (!f.is_object() || !f.contains("name") || !f["name"].is_string() || !f.contains("bytes") ||
          !f["bytes"].is_number_unsigned() || !f.contains("fnv1a64") || !f["fnv1a64"].is_string())
        return summary + ": an entry of \"files\" is malformed";
      const std::string name = f["name"].get<std::string>();
      const fs::path rel(name);
      if (name.empty() || rel.is_absolute() || name.find("..") != std::string::npos)
        return summary + ": lists a file outside its folder (" + message_text(name, 60) + ")";
      listed.insert(name);
      const fs::path p = fs::path(dir) / rel;
      if (!fs::is_regular_file(p, ec)) return name + ": missing (listed in " + summary + ")";
      const auto bytes = fs::file_size(p, ec);
      const auto want = f["bytes"].get<std::uintmax_t>();
      if (ec || bytes != want)
        return name + ": " + std::to_string(bytes) + " bytes, " + summary + " lists " + std::to_string(want);
      const std::string sum = file_checksum(p.string());
      if (sum != f["fnv1a64"].get<std::string>())
        return name + ": changed (FNV-1a 64 " + sum + ", " + summary + " lists " +
               message_text(f["fnv1a64"].get<std::string>(), 20) + ")";
    }
  }
  for (const auto& r : required)
    if (!listed.count(r)) return r + ": not listed in " + summary;
  return {};
}

bool RunFolder::is_result_name(const std::string& rel) {
  static const std::set<std::string> fixed = {"summary.json",  "series.csv",     "radius.csv",  "series.csv.part",
                                              "radius.csv.part", "solver_stats.json",
                                              "scene.resolved.json", "checkpoint.bin", "membrane.pvd", "fluid.pvd",
                                              "run.png",       "vtk",            kOwner,
                                              // swim screen, swim calibrate
                                              "designs.csv", "screen.json", "screen.png", "calibration.json",
                                              "calibration.png", "tube_law.png", "axial_stiffness.png",
                                              // swim screen --confirm, swim optimize
                                              "confirm.json", "confirm.md", "confirm.png", "trajectory.csv",
                                              "optimum.json", "optimum.scene.json", "optimize.png"};
  if (fixed.count(rel)) return true;
  // the coarse-grid run of --error-estimate: a run folder of its own inside the run's
  static const std::string coarse = "error_estimate/coarse/";
  if (rel == "error_estimate" || rel == "error_estimate/coarse") return true;
  if (rel.rfind(coarse, 0) == 0) {
    const std::string in = rel.substr(coarse.size());
    return in == kLock || is_result_name(in);
  }
  static const std::regex frames(R"(vtk/(membrane_\d+\.vtp|fluid_\d+\.vti))");
  static const std::regex temps(R"((vtk/)?\.[^/]+\.tmp(-\d+)?)");
  return std::regex_match(rel, frames) || std::regex_match(rel, temps);
}

RunFolder::RunFolder(std::string dir, const RunFolderOptions& o) : dir_(std::move(dir)), summary_(o.summary) {
  const std::string shown = "\"" + dir_ + "\"";
  std::error_code ec;
  if (fs::exists(dir_, ec) && !fs::is_directory(dir_, ec))
    throw InputError(o.key, shown, "is not a folder; give a folder for the run's results");
  const bool folder_existed = fs::exists(dir_, ec);
  fs::create_directories(dir_, ec);
  if (ec) throw InputError(o.key, shown, "cannot create the output folder: " + ec.message());

  // 1. The lock: one run per folder at a time.
  const std::string lock_path = (fs::path(dir_) / kLock).string();
  const bool lock_existed = fs::exists(lock_path, ec);
  lock_fd_ = ::open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (lock_fd_ < 0)
    throw InputError(o.key, shown, std::string("cannot create the lock file .swim.lock: ") + std::strerror(errno) +
                                       " (is the folder writable?)");
  if (::flock(lock_fd_, LOCK_EX | LOCK_NB) != 0) {
    const std::string pid = read_text(lock_path, 64);
    ::close(lock_fd_);
    lock_fd_ = -1;
    throw InputError(o.key, shown,
                     "is in use by another swim run (PID " + (pid.empty() ? std::string("unknown") : pid) +
                         "); wait for it to finish or choose another --out");
  }
  const std::string me = std::to_string(::getpid());
  if (::ftruncate(lock_fd_, 0) != 0 || ::pwrite(lock_fd_, me.data(), me.size(), 0) != static_cast<ssize_t>(me.size())) {
    // the PID is only informative; the lock itself is held
  }

  try {
    // 2. What the folder holds.
    std::vector<std::string> results, foreign;
    const scene::json old_summary = read_json(fs::path(dir_) / o.summary);
    std::set<std::string> listed;
    if (old_summary.is_object() && old_summary.contains("files") && old_summary["files"].is_array())
      for (const auto& f : old_summary["files"])
        if (f.is_object() && f.contains("name") && f["name"].is_string()) listed.insert(f["name"].get<std::string>());
    for (auto it = fs::recursive_directory_iterator(dir_, ec); !ec && it != fs::recursive_directory_iterator();
         it.increment(ec)) {
      const std::string rel = fs::relative(it->path(), dir_, ec).generic_string();
      if (rel == kLock) continue;
      const bool kept = !o.keep.empty() && (rel == o.keep || rel.rfind(o.keep + "/", 0) == 0);
      (kept || is_result_name(rel) || listed.count(rel) ? results : foreign).push_back(rel);
    }
    if (ec) throw InputError(o.key, shown, "cannot list the output folder: " + ec.message());
    std::sort(results.begin(), results.end());
    std::sort(foreign.begin(), foreign.end());

    const scene::json owner = read_json(fs::path(dir_) / kOwner);
    const std::string hash = json_hash(o.resolved);
    const std::string old_tier = tier_in(owner, old_summary);
    const std::string old_status = old_summary.is_object() && old_summary.contains("status") &&
                                           old_summary["status"].is_string()
                                       ? old_summary["status"].get<std::string>()
                                       : "";

    if (o.resume) {
      // 3a. --resume: only the run this folder belongs to.
      if (!old_tier.empty() && old_tier != o.tier)
        throw InputError("--resume", shown,
                         "holds the results of a " + old_tier + " run; --resume continues only a " + o.tier +
                             " run in its own folder");
      if (!fs::exists(fs::path(dir_) / "checkpoint.bin"))
        throw InputError("--resume", shown, "holds no checkpoint.bin, so there is no run to continue");
      if (!foreign.empty())
        throw InputError("--resume", shown, "holds files swim did not write (" + list(foreign) + ")");
    } else if (!results.empty() || !foreign.empty()) {
      // 3b. A new run into a non-empty folder.
      if (!foreign.empty())
        throw InputError(o.key, shown,
                         "holds files swim did not write (" + list(foreign) +
                             "); choose an empty or new folder (they are never removed, even with --overwrite)");
      // the scene of the old run: its record, or (folders written before records existed) its summary
      const std::string old_hash = owner.is_object() ? owner.value("scene_hash", std::string())
                                   : old_summary.is_object() && old_summary.contains("scene")
                                       ? json_hash(old_summary["scene"])
                                       : "";
      // a record written before the standard FNV-1a basis holds the legacy hash of the scene
      const bool finished = old_status.rfind("running", 0) != 0 && !old_status.empty();
      const bool same_run = (old_hash == hash || old_hash == json_hash_legacy(o.resolved)) && old_tier == o.tier &&
                            (finished || !o.keep.empty());
      if (!o.overwrite && !same_run)
        throw InputError(o.key, shown,
                         "holds the results of another run (" + (old_tier.empty() ? "" : old_tier + ", ") +
                             (old_status.empty() ? "no summary" : "status \"" + message_text(old_status, 60) + "\"") +
                             ": " + list(results) +
                             "); give --overwrite to replace them, " +
                             (o.tier == "1d" || o.tier == "3d" ? "--resume to continue an interrupted 3D run, " : "") +
                             "or another --out");
      // Clear the old run's files: the summary first (it would otherwise claim them).
      fs::remove(fs::path(dir_) / o.summary, ec);
      std::sort(results.begin(), results.end(), [](const std::string& a, const std::string& b) { return a > b; });
      const bool keep = same_run && !o.overwrite && !o.keep.empty();
      for (const auto& r : results) {
        if (keep && (r == o.keep || r.rfind(o.keep + "/", 0) == 0)) continue;  // reused by this run
        fs::remove(fs::path(dir_) / r, ec);  // files first (reverse order puts vtk/x before vtk)
        if (ec) throw InputError(o.key, shown, "cannot remove the old result " + r + ": " + ec.message());
      }
    }
    // 4. This run owns the folder.
    reset_ledger(dir_);
    scene::json rec = {{"tier", o.tier}, {"scene_hash", hash}, {"pid", static_cast<long>(::getpid())}};
    if (o.resume && owner.is_object()) rec["scene_hash"] = owner.value("scene_hash", hash);
    AtomicFile f((fs::path(dir_) / kOwner).string());
    f.stream() << rec.dump(2) << "\n";
    f.commit();
  } catch (const InputError&) {
    // a refusal leaves the folder as it was: the lock file and the folder this run created go
    if (!lock_existed) ::unlink(lock_path.c_str());
    ::close(lock_fd_);
    lock_fd_ = -1;
    if (!folder_existed) fs::remove(dir_, ec);  // only when empty
    throw;
  } catch (...) {  // OutputError (exit 3: the run's record cannot be written)
    ::close(lock_fd_);
    lock_fd_ = -1;
    throw;
  }
}

RunFolder::~RunFolder() {
  if (lock_fd_ >= 0) ::close(lock_fd_);  // releases the flock; the file stays (see header)
}

bool RunFolder::mark_failed(const std::string& message) noexcept {
  const fs::path summary = fs::path(dir_) / summary_;
  try {
    scene::json s = read_json(summary);
    if (!s.is_object()) s = scene::json::object();
    s["status"] = "failed: " + message;
    s.erase("files");  // the listed files may be the partial ones
    AtomicFile f(summary.string());
    if (carries_own_checksum(summary.string())) f.stream() << json_text_with_checksum(s);
    else f.stream() << s.dump(2, ' ', false, scene::json::error_handler_t::replace) << "\n";
    f.commit();
    return true;
  } catch (...) {
    std::error_code ec;
    fs::remove(summary, ec);
    return false;
  }
}

}  // namespace swim::output
