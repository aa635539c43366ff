#pragma once
// HeldBuffer: one buffer an object keeps between calls, for memory accounting (what a server
// pays per run while it waits for the next chunk). `allocated` is the buffer's capacity in
// bytes (Eigen allocates exactly rows x cols x sizeof(scalar)), `held` the bytes of what it
// holds now (allocated - held is spare room kept to avoid a reallocation).
#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

namespace dynid::signal {

struct HeldBuffer {
  std::string name;
  std::size_t allocated = 0;
  std::size_t held = 0;
};

/// The accounting of a dense matrix of which `held_rows` rows are in use.
template <class Derived>
HeldBuffer held_buffer(std::string name, const Eigen::DenseBase<Derived>& m,
                       Eigen::Index held_rows) {
  const auto bytes = [&](Eigen::Index rows) {
    return static_cast<std::size_t>(rows * m.cols()) * sizeof(typename Derived::Scalar);
  };
  return {std::move(name), bytes(m.rows()), bytes(held_rows)};
}

}  // namespace dynid::signal
