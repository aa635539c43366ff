#pragma once
// Cancellation: a long computation (the residual loop, SIMEX, a reprocess of a stored run) stops
// at its next cancellation point once nobody wants its answer any more: the server is stopping,
// or the client that asked has gone.
//
// Contract:
// - A Cancellation is shared by whoever may cancel and the computation. cancel(reason) is
//   thread-safe and idempotent (the first reason is kept).
// - A CancellationScope installs one for the current thread for the scope's lifetime (scopes
//   nest: the innermost counts). cancellation_point() throws Cancelled with the reason when the
//   installed one is cancelled; otherwise, or with none installed, it does nothing (one atomic
//   load), so library callers that never cancel pay nothing.
// - Cancelled is not an InputError: the request was valid. The computations that call
//   cancellation_point() only read their inputs, so nothing is left half-changed.
//
// Why a thread-local scope rather than an argument: the points sit deep in pure functions (each
// candidate's fit, each noise draw, each round of a trace), and an argument would run through
// every signature between the server and them for a concern none of those functions has.
#include <atomic>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>

namespace dynid {

class Cancelled : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Cancellation {
 public:
  void cancel(const std::string& reason);
  bool cancelled() const { return cancelled_.load(std::memory_order_acquire); }
  /// The first reason given; empty while not cancelled.
  std::string reason() const;

 private:
  std::atomic<bool> cancelled_{false};
  mutable std::mutex mutex_;
  std::string reason_;
};

class CancellationScope {
 public:
  explicit CancellationScope(std::shared_ptr<const Cancellation> cancellation);
  CancellationScope(const CancellationScope&) = delete;
  CancellationScope& operator=(const CancellationScope&) = delete;
  ~CancellationScope();

 private:
  std::shared_ptr<const Cancellation> previous_;
};

/// Throws Cancelled("cancelled: <reason>") when this thread's installed Cancellation is cancelled.
void cancellation_point();

}  // namespace dynid
