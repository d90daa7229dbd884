#include "common/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <streambuf>

#include "common/checksum.hpp"
#include "common/errors.hpp"

namespace swim::output {
namespace fs = std::filesystem;

namespace {

std::string reason_of(int err) {
  if (err == ENOSPC) return "disk full";
  if (err == EDQUOT) return "disk quota exceeded";
  if (err == EROFS) return "read-only file system";
  if (err == EACCES || err == EPERM) return "permission denied";
  if (err == EISDIR) return "a directory is in the way";
  return std::strerror(err);
}

std::string key_of(const std::string& dir) {
  std::string k = fs::path(dir.empty() ? "." : dir).lexically_normal().string();
  while (k.size() > 1 && k.back() == '/') k.pop_back();
  return k;
}

struct Ledger {
  std::mutex mutex;
  // folder -> records in commit order
  std::map<std::string, std::vector<FileRecord>> files;
  std::map<std::string, Failure> failures;  // folder -> first failure (file name in that folder)
};

Ledger& ledger() {
  static Ledger l;
  return l;
}

/// Forget the ledger record of `path` (none: nothing happens).
void unrecord(const std::string& path) {
  const fs::path p(path);
  Ledger& l = ledger();
  std::lock_guard lock(l.mutex);
  auto& v = l.files[key_of(p.parent_path().string())];
  const std::string name = p.filename().string();
  for (auto it = v.begin(); it != v.end(); ++it)
    if (it->name == name) {
      v.erase(it);
      break;
    }
}

void record(const std::string& path, std::uintmax_t bytes, std::uint64_t sum) {
  unrecord(path);
  const fs::path p(path);
  Ledger& l = ledger();
  std::lock_guard lock(l.mutex);
  l.files[key_of(p.parent_path().string())].push_back({p.filename().string(), bytes, hex64(sum)});
}

bool inside(const std::string& folder, const std::string& dir) {
  if (folder == dir) return true;
  return folder.size() > dir.size() && folder.compare(0, dir.size(), dir) == 0 && folder[dir.size()] == '/';
}

// An output stream buffer over a file descriptor that keeps the errno of a failed write,
// counts bytes and checksums them; optionally fails after a byte budget (test hook).
class FdBuf : public std::streambuf {
 public:
  /// bytes, sum: what the file already holds (a continued part file).
  FdBuf(int fd, long long fail_after, std::uintmax_t bytes = 0, std::uint64_t sum = kFnv1a64Offset)
      : fd_(fd), fail_after_(fail_after), bytes_(bytes), sum_(sum) {
    setp(buf_, buf_ + sizeof buf_);
  }
  int error() const { return error_; }
  std::uintmax_t bytes() const { return bytes_; }
  /// Bytes written to the buffer and not yet to the file.
  std::uintmax_t pending() const { return static_cast<std::uintmax_t>(pptr() - pbase()); }
  std::uint64_t checksum() const { return sum_; }

 protected:
  int_type overflow(int_type c) override {
    if (!drain()) return traits_type::eof();
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(c);
      pbump(1);
    }
    return traits_type::not_eof(c);
  }
  int sync() override { return drain() ? 0 : -1; }

 private:
  bool drain() {
    if (error_) return false;
    const char* p = pbase();
    std::size_t n = static_cast<std::size_t>(pptr() - pbase());
    sum_ = fnv1a64(p, n, sum_);
    while (n > 0) {
      std::size_t chunk = n;
      if (fail_after_ >= 0) {
        const long long room = fail_after_ - static_cast<long long>(bytes_);
        if (room <= 0) {
          error_ = ENOSPC;
          return false;
        }
        chunk = std::min<std::size_t>(chunk, static_cast<std::size_t>(room));
      }
      const ssize_t w = ::write(fd_, p, chunk);
      if (w < 0) {
        if (errno == EINTR) continue;
        error_ = errno;
        return false;
      }
      p += w;
      n -= static_cast<std::size_t>(w);
      bytes_ += static_cast<std::uintmax_t>(w);
    }
    setp(buf_, buf_ + sizeof buf_);
    return true;
  }

  int fd_;
  long long fail_after_;
  int error_ = 0;
  std::uintmax_t bytes_;
  std::uint64_t sum_;
  char buf_[1 << 16];
};

// SWIM_TEST_FAIL_WRITE=<name>[:<bytes>]: the byte budget for a file of that name (a name with a
// '/' is matched against the end of the file's path: "coarse/radius.csv"), else -1.
long long injected_budget(const std::string& path) {
  const std::string name = fs::path(path).filename().string();
  const char* e = std::getenv("SWIM_TEST_FAIL_WRITE");
  if (!e || !*e) return -1;
  std::string spec(e);
  long long budget = 0;
  if (const auto c = spec.rfind(':'); c != std::string::npos) {
    budget = std::atoll(spec.c_str() + c + 1);
    spec = spec.substr(0, c);
  }
  if (spec.find('/') == std::string::npos) return spec == name ? budget : -1;
  const bool tail = path.size() > spec.size() && path.compare(path.size() - spec.size(), spec.size(), spec) == 0 &&
                    path[path.size() - spec.size() - 1] == '/';
  return path == spec || tail ? budget : -1;
}

/// Flush and check the stream, close the file and rename `from` to `to`. Any failure is
/// noted in the ledger and thrown as the OutputError naming `to`; `from` is removed then
/// when `discard` (a temporary file), kept otherwise (a part file: partial results).
void publish(int& fd, FdBuf& buf, std::ostream& stream, const std::string& from, const std::string& to,
             bool discard) {
  const auto fail = [&](int err) {
    if (fd >= 0) ::close(fd);
    fd = -1;
    if (discard) ::unlink(from.c_str());
    note_failure(to, reason_of(err));
    throw OutputError(fs::path(to).filename().string(), reason_of(err));
  };
  stream.flush();
  if (buf.error()) fail(buf.error());
  if (!stream) fail(EIO);
  const int f = fd;
  fd = -1;
  if (::close(f) != 0) fail(errno);
  if (::rename(from.c_str(), to.c_str()) != 0) fail(errno);
}

}  // namespace

struct AtomicFile::Impl {
  std::string tmp;
  int fd = -1;
  std::unique_ptr<FdBuf> buf;
  std::unique_ptr<std::ostream> stream;
};

AtomicFile::AtomicFile(std::string path) : path_(std::move(path)), impl_(std::make_unique<Impl>()) {
  const fs::path p(path_);
  const std::string name = p.filename().string();
  impl_->tmp = (p.parent_path() / ("." + name + ".tmp-" + std::to_string(::getpid()))).string();
  impl_->fd = ::open(impl_->tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (impl_->fd < 0) {
    const int err = errno;
    note_failure(path_, reason_of(err));
    throw OutputError(name, reason_of(err));
  }
  impl_->buf = std::make_unique<FdBuf>(impl_->fd, injected_budget(path_));
  impl_->stream = std::make_unique<std::ostream>(impl_->buf.get());
}

AtomicFile::~AtomicFile() {
  if (committed_) return;
  if (impl_->fd >= 0) ::close(impl_->fd);
  ::unlink(impl_->tmp.c_str());
}

std::ostream& AtomicFile::stream() { return *impl_->stream; }

void AtomicFile::commit() {
  if (committed_) return;
  publish(impl_->fd, *impl_->buf, *impl_->stream, impl_->tmp, path_, true);
  committed_ = true;
  record(path_, impl_->buf->bytes(), impl_->buf->checksum());
}

// ---- PartFile -------------------------------------------------------------------------

struct PartFile::Impl {
  int fd = -1;
  std::unique_ptr<FdBuf> buf;
  std::unique_ptr<std::ostream> stream;
};

namespace {
/// Checksum of the first `bytes` bytes of a file; false when it is shorter or unreadable.
bool prefix_checksum(const std::string& path, std::uintmax_t bytes, std::uint64_t& sum) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  sum = kFnv1a64Offset;
  char b[1 << 16];
  std::uintmax_t left = bytes;
  while (left > 0) {
    in.read(b, static_cast<std::streamsize>(std::min<std::uintmax_t>(left, sizeof b)));
    const auto got = static_cast<std::uintmax_t>(in.gcount());
    if (got == 0) return false;
    sum = fnv1a64(b, static_cast<std::size_t>(got), sum);
    left -= got;
  }
  return true;
}
}  // namespace

PartFile::PartFile(std::string path) : path_(std::move(path)), impl_(std::make_unique<Impl>()) {
  open(O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, Mark{});
}

PartFile::PartFile(std::string path, Mark from) : path_(std::move(path)), impl_(std::make_unique<Impl>()) {
  if (!matches(path_, from))
    throw InputError("--resume", "\"" + part_path() + "\"",
                     "the partial results do not match the checkpoint (missing, shorter or changed); run the scene "
                     "again without --resume, with --overwrite to replace this folder's interrupted results");
  // a run that ended (failed, e.g. at its time limit) published its part file: continue it
  if (!fs::exists(part_path()) && ::rename(path_.c_str(), part_path().c_str()) != 0) {
    const int err = errno;
    note_failure(path_, reason_of(err));
    throw OutputError(fs::path(path_).filename().string(), reason_of(err));
  }
  open(O_WRONLY | O_CLOEXEC, from);
  if (::ftruncate(impl_->fd, static_cast<off_t>(from.bytes)) != 0 ||
      ::lseek(impl_->fd, static_cast<off_t>(from.bytes), SEEK_SET) < 0) {
    const int err = errno;
    ::close(impl_->fd);
    impl_->fd = -1;
    note_failure(path_, reason_of(err));
    throw OutputError(fs::path(part_path()).filename().string(), reason_of(err));
  }
}

void PartFile::open(int flags, Mark from) {
  const std::string part = part_path();
  const std::string name = fs::path(part).filename().string();
  impl_->fd = ::open(part.c_str(), flags, 0644);
  if (impl_->fd < 0) {
    const int err = errno;
    note_failure(path_, reason_of(err));
    throw OutputError(name, reason_of(err));
  }
  long long budget = injected_budget(path_);
  if (budget >= 0) budget += static_cast<long long>(from.bytes);
  impl_->buf = std::make_unique<FdBuf>(impl_->fd, budget, from.bytes, from.checksum);
  impl_->stream = std::make_unique<std::ostream>(impl_->buf.get());
}

PartFile::~PartFile() {
  if (committed_ || impl_->fd < 0) return;
  impl_->stream->flush();  // best effort: the rows so far are partial results
  ::close(impl_->fd);
}

std::ostream& PartFile::stream() { return *impl_->stream; }

std::uintmax_t PartFile::bytes() const { return impl_->buf->bytes() + impl_->buf->pending(); }

bool PartFile::matches(const std::string& path, Mark from) {
  std::uint64_t sum = 0;
  const std::string part = path + ".part";
  return prefix_checksum(fs::exists(part) ? part : path, from.bytes, sum) && sum == from.checksum;
}

PartFile::Mark PartFile::sync() {
  const std::string name = fs::path(path_).filename().string();
  impl_->stream->flush();
  int err = impl_->buf->error();
  if (!err && !*impl_->stream) err = EIO;
  if (err) {
    note_failure(path_, reason_of(err));
    throw OutputError(name, reason_of(err));
  }
  const Mark m{impl_->buf->bytes(), impl_->buf->checksum()};
  record(part_path(), m.bytes, m.checksum);
  return m;
}

void PartFile::commit() {
  if (committed_) return;
  publish(impl_->fd, *impl_->buf, *impl_->stream, part_path(), path_, false);
  committed_ = true;
  unrecord(part_path());
  record(path_, impl_->buf->bytes(), impl_->buf->checksum());
}

std::vector<FileRecord> committed_files(const std::string& dir) {
  const std::string d = key_of(dir);
  Ledger& l = ledger();
  std::lock_guard lock(l.mutex);
  std::vector<FileRecord> out;
  for (const auto& [folder, v] : l.files) {
    if (!inside(folder, d)) continue;
    const std::string prefix = folder == d ? "" : folder.substr(d.size() + 1) + "/";
    for (const auto& r : v) out.push_back({prefix + r.name, r.bytes, r.fnv1a64});
  }
  return out;
}

Failure first_failure(const std::string& dir) {
  const std::string d = key_of(dir);
  Ledger& l = ledger();
  std::lock_guard lock(l.mutex);
  for (const auto& [folder, f] : l.failures)
    if (inside(folder, d)) return {folder == d ? f.file : folder.substr(d.size() + 1) + "/" + f.file, f.reason};
  return {};
}

void note_failure(const std::string& path, const std::string& reason) {
  const fs::path p(path);
  Ledger& l = ledger();
  std::lock_guard lock(l.mutex);
  l.failures.emplace(key_of(p.parent_path().string()), Failure{p.filename().string(), reason});
}

void reset_ledger(const std::string& dir) {
  const std::string d = key_of(dir);
  Ledger& l = ledger();
  std::lock_guard lock(l.mutex);
  for (auto it = l.files.begin(); it != l.files.end();) it = inside(it->first, d) ? l.files.erase(it) : std::next(it);
  for (auto it = l.failures.begin(); it != l.failures.end();)
    it = inside(it->first, d) ? l.failures.erase(it) : std::next(it);
}

bool adopt(const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return false;
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::uint64_t sum = kFnv1a64Offset;
  std::uintmax_t bytes = 0;
  char b[1 << 16];
  while (in) {
    in.read(b, sizeof b);
    const auto got = static_cast<std::size_t>(in.gcount());
    sum = fnv1a64(b, got, sum);
    bytes += got;
  }
  record(path, bytes, sum);
  return true;
}

std::string file_checksum(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "";
  std::uint64_t sum = kFnv1a64Offset;
  char b[1 << 16];
  while (in) {
    in.read(b, sizeof b);
    sum = fnv1a64(b, static_cast<std::size_t>(in.gcount()), sum);
  }
  return hex64(sum);
}

}  // namespace swim::output
