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

void record(const std::string& path, std::uintmax_t bytes, std::uint64_t sum) {
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
  v.push_back({name, bytes, hex64(sum)});
}

bool inside(const std::string& folder, const std::string& dir) {
  if (folder == dir) return true;
  return folder.size() > dir.size() && folder.compare(0, dir.size(), dir) == 0 && folder[dir.size()] == '/';
}

// An output stream buffer over a file descriptor that keeps the errno of a failed write,
// counts bytes and checksums them; optionally fails after a byte budget (test hook).
class FdBuf : public std::streambuf {
 public:
  FdBuf(int fd, long long fail_after) : fd_(fd), fail_after_(fail_after) { setp(buf_, buf_ + sizeof buf_); }
  int error() const { return error_; }
  std::uintmax_t bytes() const { return bytes_; }
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
  std::uintmax_t bytes_ = 0;
  std::uint64_t sum_ = kFnv1a64Offset;
  char buf_[1 << 16];
};

// SWIM_TEST_FAIL_WRITE=<name>[:<bytes>]: the byte budget for a file of that name, else -1.
long long injected_budget(const std::string& name) {
  const char* e = std::getenv("SWIM_TEST_FAIL_WRITE");
  if (!e || !*e) return -1;
  std::string spec(e);
  long long budget = 0;
  if (const auto c = spec.rfind(':'); c != std::string::npos) {
    budget = std::atoll(spec.c_str() + c + 1);
    spec = spec.substr(0, c);
  }
  return spec == name ? budget : -1;
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
  impl_->buf = std::make_unique<FdBuf>(impl_->fd, injected_budget(name));
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
  const std::string name = fs::path(path_).filename().string();
  const auto fail = [&](int err) {
    ::close(impl_->fd);
    impl_->fd = -1;
    ::unlink(impl_->tmp.c_str());
    note_failure(path_, reason_of(err));
    throw OutputError(name, reason_of(err));
  };
  impl_->stream->flush();
  if (impl_->buf->error()) fail(impl_->buf->error());
  if (!*impl_->stream) fail(EIO);
  const int fd = impl_->fd;
  impl_->fd = -1;
  if (::close(fd) != 0) {
    const int err = errno;
    ::unlink(impl_->tmp.c_str());
    note_failure(path_, reason_of(err));
    throw OutputError(name, reason_of(err));
  }
  if (::rename(impl_->tmp.c_str(), path_.c_str()) != 0) {
    const int err = errno;
    ::unlink(impl_->tmp.c_str());
    note_failure(path_, reason_of(err));
    throw OutputError(name, reason_of(err));
  }
  committed_ = true;
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
