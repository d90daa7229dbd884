// Binary checkpoints of 3D runs: a little-endian archive of named records (doubles,
// integers, strings, arrays of doubles), read back by name in any order.
//
//   header   "SWIM3DCK"  u32 format version  u64 scene hash  u64 payload bytes  u64 payload FNV-1a 64
//   payload  records: u8 kind ('d', 'i', 's', 'a'), u32 name length, name, value
//            (d: f64; i: i64; s: u64 length + bytes; a: u64 count + f64 values)
//   trailer  "END!"
//
// The scene hash identifies the run a checkpoint belongs to; the payload checksum
// detects any changed byte. Writing goes through output::AtomicFile (temporary file in
// the same folder, checked close, rename), so a failed or interrupted write never
// destroys the previous checkpoint, and a failure is a swim::OutputError naming the
// file. Doubles are stored bit for bit: a run resumed from a checkpoint continues
// from exactly the state that was saved.
//
// Every failure to read is an InputError (key "--resume") that names the file, says
// what is wrong and what to do; the run-level checks of the restored values (times,
// positions, sizes) are in run3d_checkpoint.hpp.
#pragma once

#include <concepts>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace swim::full3d {

/// 5: checksums and the scene hash with the standard FNV-1a 64 offset basis (version 4 used
/// the legacy basis, common/checksum.hpp; such a checkpoint is refused with a message saying so).
inline constexpr std::uint32_t kCheckpointVersion = 6;

class CheckpointWriter {
 public:
  /// scene_hash: the hash of the scene the run belongs to (checked on reading).
  explicit CheckpointWriter(std::uint64_t scene_hash) : scene_hash_(scene_hash) {}
  void put(const std::string& name, double v);
  void put(const std::string& name, std::int64_t v);
  void put(const std::string& name, const std::string& s);
  void put(const std::string& name, const double* v, std::size_t n);
  void put(const std::string& name, const std::vector<double>& v) { put(name, v.data(), v.size()); }
  /// Writes atomically. Throws swim::OutputError naming the file on any I/O failure; the
  /// previous file under `path` is then untouched.
  void save(const std::string& path) const;

 private:
  std::uint64_t scene_hash_;
  std::string buf_;
  void raw(const void* p, std::size_t n) { buf_.append(static_cast<const char*>(p), n); }
  void name(const std::string& n, char kind);
};

class CheckpointReader {
 public:
  /// Reads and checks the file: present, complete, this format version, checksum intact,
  /// records well formed, names unique, and written for the scene with `scene_hash`.
  /// Throws swim::InputError (key "--resume") naming the file otherwise.
  CheckpointReader(const std::string& path, std::uint64_t scene_hash);

  bool has(const std::string& name) const { return records_.count(name) != 0; }
  double get_double(const std::string& name) const;
  std::int64_t get_int(const std::string& name) const;
  std::string get_string(const std::string& name) const;
  std::vector<double> get_vector(const std::string& name) const;
  /// Number of values of an array record.
  std::size_t size_of(const std::string& name) const;
  /// Reads an array into v, which must have the stored size (else "different grid or mesh").
  void get_into(const std::string& name, double* v, std::size_t n) const;
  /// The first double or array record (in file order) holding a NaN or infinity, "" if none.
  std::string first_non_finite() const;

  /// An InputError for this file: "<what>; <remedy>" with the standard remedy.
  [[noreturn]] void damaged(const std::string& what) const;
  const std::string& path() const { return path_; }

 private:
  struct Record {
    char kind;
    std::size_t pos;    ///< offset of the value in buf_
    std::size_t count;  ///< bytes (s) or values (a); 1 for d and i
    std::size_t order;  ///< position in the file
  };
  std::string buf_, path_;
  std::map<std::string, Record> records_;
  const Record& find(const std::string& name, char kind) const;
};

/// A part of a run lists its records once, as calls f(name, member) (or f(name, data, n)
/// for an array of fixed size), and runs that list with CheckpointOut to write and with
/// CheckpointIn to read: the names of both directions cannot drift apart. Integers and
/// flags are stored as 64-bit integers.
class CheckpointOut {
 public:
  explicit CheckpointOut(CheckpointWriter& w) : w_(w) {}
  void operator()(const std::string& name, double v) { w_.put(name, v); }
  template <std::integral I>
  void operator()(const std::string& name, I v) { w_.put(name, std::int64_t(v)); }
  void operator()(const std::string& name, const std::vector<double>& v) { w_.put(name, v); }
  void operator()(const std::string& name, const double* v, std::size_t n) { w_.put(name, v, n); }

 private:
  CheckpointWriter& w_;
};

class CheckpointIn {
 public:
  explicit CheckpointIn(const CheckpointReader& r) : r_(r) {}
  void operator()(const std::string& name, double& v) { v = r_.get_double(name); }
  template <std::integral I>
  void operator()(const std::string& name, I& v) { v = static_cast<I>(r_.get_int(name)); }
  void operator()(const std::string& name, std::vector<double>& v) { v = r_.get_vector(name); }
  void operator()(const std::string& name, double* v, std::size_t n) { r_.get_into(name, v, n); }

 private:
  const CheckpointReader& r_;
};

}  // namespace swim::full3d
