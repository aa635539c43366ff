#pragma once
// Entity: owns one Cyclone entity handle (participant, topic, reader, writer, waitset,
// condition) and deletes it on destruction. Move-only.
//
// Deleting an entity deletes its children in Cyclone, so a child wrapper that outlives its
// parent holds a dead handle; its own delete then fails harmlessly (the result is ignored).
// Still, declare parents before children so they go in the natural order.
#include <dds/dds.h>

#include <utility>

namespace dynid::dds {

class Entity {
 public:
  Entity() = default;
  explicit Entity(dds_entity_t handle) : handle_(handle) {}
  Entity(const Entity&) = delete;
  Entity& operator=(const Entity&) = delete;
  Entity(Entity&& other) noexcept : handle_(std::exchange(other.handle_, 0)) {}
  Entity& operator=(Entity&& other) noexcept {
    if (this != &other) {
      reset();
      handle_ = std::exchange(other.handle_, 0);
    }
    return *this;
  }
  ~Entity() { reset(); }

  dds_entity_t get() const { return handle_; }
  explicit operator bool() const { return handle_ > 0; }

 private:
  void reset() {
    if (handle_ > 0) dds_delete(handle_);
    handle_ = 0;
  }
  dds_entity_t handle_ = 0;
};

}  // namespace dynid::dds
