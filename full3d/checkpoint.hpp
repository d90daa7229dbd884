// Binary checkpoints of 3D runs: a flat little-endian archive of tagged
// records (doubles, integers, strings, arrays of doubles) with a magic header,
// a format version and a trailing end marker. Writing goes to "<path>.tmp" and
// is renamed over <path> when complete, so an interrupted write never destroys
// the previous checkpoint. Doubles are stored bit for bit: a run resumed from a
// checkpoint continues from exactly the state that was saved.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace swim::full3d {

class CheckpointWriter {
 public:
  void put(const std::string& tag, double v);
  void put(const std::string& tag, std::int64_t v);
  void put(const std::string& tag, const std::string& s);
  void put(const std::string& tag, const double* v, std::size_t n);
  void put(const std::string& tag, const std::vector<double>& v) { put(tag, v.data(), v.size()); }
  /// Writes atomically (tmp + rename). Throws std::runtime_error on I/O failure.
  void save(const std::string& path) const;

 private:
  std::string buf_;
  void raw(const void* p, std::size_t n) { buf_.append(static_cast<const char*>(p), n); }
  void tag(const std::string& t, char kind);
};

class CheckpointReader {
 public:
  /// Throws swim::InputError (key "--resume") when the file is missing, truncated or of
  /// another format version.
  explicit CheckpointReader(const std::string& path);
  double get_double(const std::string& tag);
  std::int64_t get_int(const std::string& tag);
  std::string get_string(const std::string& tag);
  std::vector<double> get_vector(const std::string& tag);
  /// Reads an array into v, which must already have the stored size.
  void get_into(const std::string& tag, double* v, std::size_t n);
  bool at_end() const;

 private:
  std::string buf_, path_;
  std::size_t pos_ = 0;
  void raw(void* p, std::size_t n);
  void expect(const std::string& t, char kind);
};

}  // namespace swim::full3d
