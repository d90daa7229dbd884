#include "full3d/checkpoint.hpp"

#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

#include "common/atomic_file.hpp"
#include "common/checksum.hpp"
#include "common/errors.hpp"

namespace swim::full3d {

namespace {

constexpr char kMagic[8] = {'S', 'W', 'I', 'M', '3', 'D', 'C', 'K'};
constexpr char kEnd[4] = {'E', 'N', 'D', '!'};
// magic, version, scene hash, payload bytes, payload checksum
constexpr std::size_t kHeader = sizeof kMagic + sizeof(std::uint32_t) + 3 * sizeof(std::uint64_t);

constexpr const char* kRemedy =
    "run the scene again without --resume, with --overwrite to replace this folder's interrupted results (or "
    "resume from an intact copy of the file)";

template <class T>
T load(const std::string& buf, std::size_t pos) {
  T v;
  std::memcpy(&v, buf.data() + pos, sizeof v);
  return v;
}

const char* kind_name(char k) {
  switch (k) {
    case 'd': return "a number";
    case 'i': return "an integer";
    case 's': return "a text";
    case 'a': return "an array";
    default: return "of unknown kind";
  }
}

}  // namespace

void CheckpointWriter::name(const std::string& n, char kind) {
  const std::uint32_t len = static_cast<std::uint32_t>(n.size());
  raw(&kind, 1);
  raw(&len, sizeof len);
  raw(n.data(), len);
}

void CheckpointWriter::put(const std::string& n, double v) {
  name(n, 'd');
  raw(&v, sizeof v);
}
void CheckpointWriter::put(const std::string& n, std::int64_t v) {
  name(n, 'i');
  raw(&v, sizeof v);
}
void CheckpointWriter::put(const std::string& n, const std::string& s) {
  name(n, 's');
  const std::uint64_t len = s.size();
  raw(&len, sizeof len);
  raw(s.data(), s.size());
}
void CheckpointWriter::put(const std::string& n, const double* v, std::size_t count) {
  name(n, 'a');
  const std::uint64_t m = count;
  raw(&m, sizeof m);
  if (count > 0) raw(v, count * sizeof(double));  // an empty array has no storage (v may be null)
}

void CheckpointWriter::save(const std::string& path) const {
  output::AtomicFile f(path);
  std::ostream& out = f.stream();
  const std::uint64_t bytes = buf_.size(), sum = fnv1a64(buf_.data(), buf_.size());
  out.write(kMagic, sizeof kMagic);
  out.write(reinterpret_cast<const char*>(&kCheckpointVersion), sizeof kCheckpointVersion);
  out.write(reinterpret_cast<const char*>(&scene_hash_), sizeof scene_hash_);
  out.write(reinterpret_cast<const char*>(&bytes), sizeof bytes);
  out.write(reinterpret_cast<const char*>(&sum), sizeof sum);
  out.write(buf_.data(), std::streamsize(buf_.size()));
  out.write(kEnd, sizeof kEnd);
  f.commit();
}

void CheckpointReader::damaged(const std::string& what) const {
  throw InputError("--resume", path_, what + "; " + kRemedy);
}

CheckpointReader::CheckpointReader(const std::string& path, std::uint64_t scene_hash) : path_(path) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw InputError("--resume", path, "no checkpoint file found (a 3D run writes checkpoint.bin into its output folder)");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string all = ss.str();
  if (all.size() < kHeader + sizeof kEnd)
    damaged("the checkpoint is truncated (" + std::to_string(all.size()) + " bytes, shorter than its header)");
  if (std::memcmp(all.data(), kMagic, sizeof kMagic) != 0) damaged("not a swim 3D checkpoint (wrong magic bytes)");
  std::size_t at = sizeof kMagic;
  const auto version = load<std::uint32_t>(all, at);
  at += sizeof version;
  const auto stored_scene = load<std::uint64_t>(all, at);
  at += sizeof stored_scene;
  const auto bytes = load<std::uint64_t>(all, at);
  at += sizeof bytes;
  const auto sum = load<std::uint64_t>(all, at);
  if (version == 4)
    damaged("checkpoint format version 4, written by a swim whose checksums used a non-standard FNV-1a offset basis; "
            "this swim reads version " + std::to_string(kCheckpointVersion) + " only");
  if (version != kCheckpointVersion)
    damaged("checkpoint format version " + std::to_string(version) + ", this swim reads version " +
            std::to_string(kCheckpointVersion) + " (written by another swim version, or damaged)");
  const bool ends = std::memcmp(all.data() + all.size() - sizeof kEnd, kEnd, sizeof kEnd) == 0;
  if (bytes != all.size() - kHeader - sizeof kEnd || !ends)
    damaged("the checkpoint is truncated or has trailing bytes (" + std::to_string(all.size()) +
            " bytes, its header says " + std::to_string(bytes) + " bytes of records)");
  buf_ = all.substr(kHeader, bytes);
  all.clear();
  if (const std::uint64_t now = fnv1a64(buf_.data(), buf_.size()); now != sum)
    damaged("the checkpoint is damaged: its checksum does not match its content (" + hex64(now) + ", written " +
            hex64(sum) + ")");
  if (stored_scene != scene_hash)
    throw InputError("--resume", path_,
                     "the checkpoint was written for a different scene (only full3d.checkpoint_interval, "
                     "full3d.threads, full3d.time_limit, axi.checkpoint_interval and axi.time_limit may change on "
                     "resume); resume with the scene it was "
                     "written for, or run this scene without --resume (with --overwrite to replace the folder's "
                     "results, or into another folder)");
  // the record index: every record well formed, names unique
  std::size_t pos = 0;
  auto need = [&](std::size_t n) {
    if (n > buf_.size() - pos) damaged("the checkpoint's records are malformed (a record runs past the end)");
  };
  while (pos < buf_.size()) {
    need(1 + sizeof(std::uint32_t));
    const char kind = buf_[pos];
    const auto len = load<std::uint32_t>(buf_, pos + 1);
    pos += 1 + sizeof len;
    need(len);
    std::string name = buf_.substr(pos, len);
    pos += len;
    Record r{kind, 0, 1, records_.size()};
    if (kind == 'd' || kind == 'i') {
      need(8);
    } else if (kind == 's' || kind == 'a') {
      need(sizeof(std::uint64_t));
      const auto n = load<std::uint64_t>(buf_, pos);
      pos += sizeof n;
      r.count = n;
      if (kind == 'a' && n > (buf_.size() - pos) / sizeof(double)) need(buf_.size() + 1);
      need(kind == 'a' ? n * sizeof(double) : n);
    } else {
      damaged("the checkpoint's records are malformed (unknown record kind " + std::to_string(int(kind)) + ")");
    }
    r.pos = pos;
    pos += kind == 's' ? r.count : kind == 'a' ? r.count * sizeof(double) : 8;
    if (!records_.emplace(name, r).second) damaged("the checkpoint holds the record '" + name + "' twice");
  }
}

const CheckpointReader::Record& CheckpointReader::find(const std::string& name, char kind) const {
  const auto it = records_.find(name);
  if (it == records_.end()) damaged("the checkpoint has no record '" + name + "'");
  if (it->second.kind != kind)
    damaged(std::string("the checkpoint's record '") + name + "' is " + kind_name(it->second.kind) + ", expected " +
            kind_name(kind));
  return it->second;
}

double CheckpointReader::get_double(const std::string& name) const { return load<double>(buf_, find(name, 'd').pos); }
std::int64_t CheckpointReader::get_int(const std::string& name) const {
  return load<std::int64_t>(buf_, find(name, 'i').pos);
}
std::string CheckpointReader::get_string(const std::string& name) const {
  const Record& r = find(name, 's');
  return buf_.substr(r.pos, r.count);
}
std::size_t CheckpointReader::size_of(const std::string& name) const { return find(name, 'a').count; }
std::vector<double> CheckpointReader::get_vector(const std::string& name) const {
  const Record& r = find(name, 'a');
  std::vector<double> v(r.count);
  if (r.count > 0) std::memcpy(v.data(), buf_.data() + r.pos, r.count * sizeof(double));
  return v;
}
void CheckpointReader::get_into(const std::string& name, double* v, std::size_t n) const {
  const Record& r = find(name, 'a');
  if (r.count != n)
    damaged("the checkpoint's array '" + name + "' has " + std::to_string(r.count) + " values, this scene needs " +
            std::to_string(n) + " (a different grid or mesh)");
  if (n > 0) std::memcpy(v, buf_.data() + r.pos, n * sizeof(double));
}

std::string CheckpointReader::first_non_finite() const {
  std::string first;
  std::size_t first_order = records_.size();
  for (const auto& [name, r] : records_) {
    if (r.order >= first_order || (r.kind != 'd' && r.kind != 'a')) continue;
    for (std::size_t k = 0; k < r.count; ++k)
      if (!std::isfinite(load<double>(buf_, r.pos + k * sizeof(double)))) {
        first = name;
        first_order = r.order;
        break;
      }
  }
  return first;
}

}  // namespace swim::full3d
