#include "reduced1d/sample_pipe.hpp"

#include <algorithm>
#include <cstdint>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

namespace swim::reduced1d::detail {

namespace {
// Spins before a side sleeps: 0.5 to 1 ms on the AMD EPYC of docs/performance-1d.md (a pause
// measured at 25 and 49 ns); longer than the integration between two samples, short against a
// run.
constexpr int kSpins = 20000;

inline void relax() {
#if defined(__x86_64__) || defined(__i386__)
  _mm_pause();
#endif
}
}  // namespace

SamplePipe::SamplePipe(std::size_t record_size, Consumer consumer, std::size_t slots)
    : stride_((record_size + 7) / 8 * 8), slots_(slots), buffer_(stride_ * slots + 8), consumer_(std::move(consumer)) {
  const std::uintptr_t a = reinterpret_cast<std::uintptr_t>(buffer_.data());
  ring_ = buffer_.data() + ((64 - a % 64) % 64) / sizeof(double);
  thread_ = std::thread([this] { run(); });
}

SamplePipe::~SamplePipe() {
  stop_.store(true, std::memory_order_seq_cst);
  wake(consumer_sleeps_);
  thread_.join();
}

template <class Done>
void SamplePipe::wait_until(Done done, std::atomic<bool>& sleeping) {
  for (int k = 0; k < kSpins; ++k) {
    if (done()) return;
    relax();
  }
  std::unique_lock<std::mutex> lock(m_);
  sleeping.store(true, std::memory_order_seq_cst);
  cv_.wait(lock, done);
  sleeping.store(false, std::memory_order_relaxed);
}

void SamplePipe::wake(std::atomic<bool>& sleeping) {
  // The sleeper sets its flag before it tests its condition (both sequentially consistent), so
  // either it sees the change made before this call or this call sees its flag.
  if (sleeping.load(std::memory_order_seq_cst)) {
    std::lock_guard<std::mutex> lock(m_);
    cv_.notify_all();
  }
}

double* SamplePipe::slot() {
  const long c = committed_.load(std::memory_order_relaxed);
  // A full ring waits until half of it is free: where the consumer is the slower side (a run
  // streaming its rows to disk), the producer then sleeps once per half ring, not once per
  // record.
  if (c - consumed_.load(std::memory_order_seq_cst) >= long(slots_))
    wait_until([&] { return c - consumed_.load(std::memory_order_seq_cst) <= long(slots_ / 2); }, producer_sleeps_);
  return ring_ + std::size_t(c % long(slots_)) * stride_;
}

void SamplePipe::commit() {
  committed_.fetch_add(1, std::memory_order_seq_cst);
  wake(consumer_sleeps_);
}

void SamplePipe::drain() {
  const long c = committed_.load(std::memory_order_relaxed);
  wait_until([&] { return consumed_.load(std::memory_order_seq_cst) == c; }, producer_sleeps_);
  if (error_) {
    std::exception_ptr e = error_;
    error_ = nullptr;
    std::rethrow_exception(e);
  }
}

void SamplePipe::run() {
  for (long next = 0;; ++next) {
    wait_until(
        [&] {
          return committed_.load(std::memory_order_seq_cst) > next || stop_.load(std::memory_order_seq_cst);
        },
        consumer_sleeps_);
    if (committed_.load(std::memory_order_seq_cst) <= next) return;  // stopped with nothing left
    if (!failed_.load(std::memory_order_relaxed)) {
      try {
        if (!consumer_(ring_ + std::size_t(next % long(slots_)) * stride_))
          failed_.store(true, std::memory_order_release);
      } catch (...) {
        error_ = std::current_exception();
        failed_.store(true, std::memory_order_release);
      }
    }
    consumed_.store(next + 1, std::memory_order_seq_cst);
    wake(producer_sleeps_);
  }
}

}  // namespace swim::reduced1d::detail
