// A single-producer, single-consumer pipe of fixed-size records to a thread of its own.
//
// The force-driven run (force_driven.cpp) hands each output sample's state to it and goes on
// integrating while the second thread evaluates the sample's flow (the closure, the fluxes,
// the wall's energy), appends it to the result and streams it to disk. The consumer sees the
// records in the order they were committed, one at a time, so what it produces is what the
// same calls on the integrating thread would produce, bit for bit.
//
// Waiting: each side spins briefly (a sample is due every few microseconds of integration),
// then sleeps on a condition variable.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace swim::reduced1d::detail {

class SamplePipe {
 public:
  /// Consumes one record; false marks it failed, and the pipe then skips every later record.
  using Consumer = std::function<bool(const double* record)>;

  SamplePipe(std::size_t record_size, Consumer consumer, std::size_t slots = 64);
  ~SamplePipe();
  SamplePipe(const SamplePipe&) = delete;
  SamplePipe& operator=(const SamplePipe&) = delete;

  /// The next record to fill (waits while every slot is in use).
  double* slot();
  /// Hands the record returned by slot() to the consumer.
  void commit();
  /// Waits until every committed record is consumed. Rethrows an exception the consumer threw.
  void drain();
  /// A record was marked failed (or the consumer threw); later records were skipped.
  bool failed() const { return failed_.load(std::memory_order_acquire); }

 private:
  void run();
  /// Spins, then sleeps, until done() holds.
  template <class Done>
  void wait_until(Done done, std::atomic<bool>& sleeping);
  void wake(std::atomic<bool>& sleeping);

  const std::size_t stride_, slots_;  // a record's stride (whole cache lines), the records
  std::vector<double> buffer_;
  double* ring_;  // the records, from a cache line's start in buffer_
  Consumer consumer_;
  // each side's counter and flag on a cache line of its own (the other side reads them in
  // every wait, and a shared line would travel between the cores at every record)
  alignas(64) std::atomic<long> committed_{0};
  std::atomic<bool> producer_sleeps_{false};
  std::atomic<bool> stop_{false};
  alignas(64) std::atomic<long> consumed_{0};
  std::atomic<bool> consumer_sleeps_{false};
  std::atomic<bool> failed_{false};
  alignas(64) std::mutex m_;
  std::condition_variable cv_;
  std::exception_ptr error_;
  std::thread thread_;
};

}  // namespace swim::reduced1d::detail
