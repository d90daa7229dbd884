#include "full3d/checkpoint.hpp"

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "common/errors.hpp"

namespace swim::full3d {

namespace {
constexpr char kMagic[8] = {'S', 'W', 'I', 'M', '3', 'D', 'C', 'K'};
constexpr std::uint32_t kVersion = 1;
}  // namespace

void CheckpointWriter::tag(const std::string& t, char kind) {
  const std::uint32_t n = static_cast<std::uint32_t>(t.size());
  raw(&kind, 1);
  raw(&n, sizeof n);
  raw(t.data(), n);
}

void CheckpointWriter::put(const std::string& t, double v) {
  tag(t, 'd');
  raw(&v, sizeof v);
}
void CheckpointWriter::put(const std::string& t, std::int64_t v) {
  tag(t, 'i');
  raw(&v, sizeof v);
}
void CheckpointWriter::put(const std::string& t, const std::string& s) {
  tag(t, 's');
  const std::uint64_t n = s.size();
  raw(&n, sizeof n);
  raw(s.data(), s.size());
}
void CheckpointWriter::put(const std::string& t, const double* v, std::size_t n) {
  tag(t, 'a');
  const std::uint64_t m = n;
  raw(&m, sizeof m);
  raw(v, n * sizeof(double));
}

void CheckpointWriter::save(const std::string& path) const {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error("cannot write checkpoint " + tmp);
    out.write(kMagic, sizeof kMagic);
    out.write(reinterpret_cast<const char*>(&kVersion), sizeof kVersion);
    const std::uint64_t n = buf_.size();
    out.write(reinterpret_cast<const char*>(&n), sizeof n);
    out.write(buf_.data(), std::streamsize(buf_.size()));
    out.write("END!", 4);
    out.flush();
    if (!out) throw std::runtime_error("cannot write checkpoint " + tmp);
  }
  std::filesystem::rename(tmp, path);
}

CheckpointReader::CheckpointReader(const std::string& path) : path_(path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("--resume", path, "no checkpoint file found (a 3D run writes checkpoint.bin into its output folder)");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string all = ss.str();
  char magic[8];
  std::uint32_t version = 0;
  std::uint64_t n = 0;
  const std::size_t head = sizeof magic + sizeof version + sizeof n;
  if (all.size() < head + 4) throw InputError("--resume", path, "the checkpoint file is truncated");
  std::memcpy(magic, all.data(), sizeof magic);
  std::memcpy(&version, all.data() + sizeof magic, sizeof version);
  std::memcpy(&n, all.data() + sizeof magic + sizeof version, sizeof n);
  if (std::memcmp(magic, kMagic, sizeof magic) != 0) throw InputError("--resume", path, "not a swim 3D checkpoint");
  if (version != kVersion)
    throw InputError("--resume", path, "checkpoint format version " + std::to_string(version) + ", expected " +
                                           std::to_string(kVersion));
  if (all.size() != head + n + 4 || all.compare(head + n, 4, "END!") != 0)
    throw InputError("--resume", path, "the checkpoint file is truncated or corrupt");
  buf_ = all.substr(head, n);
}

void CheckpointReader::raw(void* p, std::size_t n) {
  if (pos_ + n > buf_.size()) throw InputError("--resume", path_, "the checkpoint file is truncated or corrupt");
  if (n > 0) std::memcpy(p, buf_.data() + pos_, n);  // an empty array has no storage (p may be null)
  pos_ += n;
}

void CheckpointReader::expect(const std::string& t, char kind) {
  char k = 0;
  std::uint32_t n = 0;
  raw(&k, 1);
  raw(&n, sizeof n);
  if (pos_ + n > buf_.size()) throw InputError("--resume", path_, "the checkpoint file is corrupt");
  const std::string got = buf_.substr(pos_, n);
  pos_ += n;
  if (k != kind || got != t)
    throw InputError("--resume", path_, "unexpected record '" + got + "' (expected '" + t + "'): written by another version");
}

double CheckpointReader::get_double(const std::string& t) {
  expect(t, 'd');
  double v;
  raw(&v, sizeof v);
  return v;
}
std::int64_t CheckpointReader::get_int(const std::string& t) {
  expect(t, 'i');
  std::int64_t v;
  raw(&v, sizeof v);
  return v;
}
std::string CheckpointReader::get_string(const std::string& t) {
  expect(t, 's');
  std::uint64_t n;
  raw(&n, sizeof n);
  std::string s(n, '\0');
  raw(s.data(), n);
  return s;
}
std::vector<double> CheckpointReader::get_vector(const std::string& t) {
  expect(t, 'a');
  std::uint64_t n;
  raw(&n, sizeof n);
  std::vector<double> v(n);
  raw(v.data(), n * sizeof(double));
  return v;
}
void CheckpointReader::get_into(const std::string& t, double* v, std::size_t n) {
  expect(t, 'a');
  std::uint64_t m;
  raw(&m, sizeof m);
  if (m != n) throw InputError("--resume", path_, "array '" + t + "' has " + std::to_string(m) + " values, expected " +
                                                      std::to_string(n) + " (different grid or mesh)");
  raw(v, n * sizeof(double));
}
bool CheckpointReader::at_end() const { return pos_ == buf_.size(); }

}  // namespace swim::full3d
