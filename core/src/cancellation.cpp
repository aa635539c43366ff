#include "dynid/cancellation.hpp"

namespace dynid {
namespace {

thread_local std::shared_ptr<const Cancellation> installed;

}  // namespace

void Cancellation::cancel(const std::string& reason) {
  std::lock_guard lock(mutex_);
  if (cancelled_.load(std::memory_order_relaxed)) return;
  reason_ = reason;
  cancelled_.store(true, std::memory_order_release);
}

std::string Cancellation::reason() const {
  std::lock_guard lock(mutex_);
  return reason_;
}

CancellationScope::CancellationScope(std::shared_ptr<const Cancellation> cancellation)
    : previous_(std::move(installed)) {
  installed = std::move(cancellation);
}

CancellationScope::~CancellationScope() {
  installed = std::move(previous_);
}

void cancellation_point() {
  const Cancellation* c = installed.get();
  if (c != nullptr && c->cancelled()) throw Cancelled("cancelled: " + c->reason());
}

}  // namespace dynid
