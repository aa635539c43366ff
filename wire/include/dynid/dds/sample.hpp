#pragma once
// Sample<T>: owns one generated wire sample (a C struct from idl/dynid.idl) and frees what its
// sequences point to with Cyclone's own allocator (dds_sample_free), on destruction.
//
// Contract: buffers inside `data` must come from dds_alloc (conversions.cpp does that, and so
// does Cyclone when a reader takes into a Sample). Move-only: moving transfers the buffers
// and leaves the source zeroed.
#include <dds/dds.h>

#include <cstring>
#include <type_traits>

#include "dynid/dds/topics.hpp"

namespace dynid::dds {

template <typename T>
class Sample {
  static_assert(std::is_trivially_copyable_v<T>, "wire samples are plain C structs");

 public:
  Sample() { std::memset(&data, 0, sizeof data); }
  Sample(const Sample&) = delete;
  Sample& operator=(const Sample&) = delete;
  Sample(Sample&& other) noexcept : publication_handle(other.publication_handle) {
    std::memcpy(&data, &other.data, sizeof data);
    std::memset(&other.data, 0, sizeof data);
  }
  Sample& operator=(Sample&& other) noexcept {
    if (this != &other) {
      release();
      publication_handle = other.publication_handle;
      std::memcpy(&data, &other.data, sizeof data);
      std::memset(&other.data, 0, sizeof data);
    }
    return *this;
  }
  ~Sample() { release(); }

  T data;
  /// The writer that sent it (dds_sample_info_t::publication_handle), 0 when not taken from a
  /// reader: a server asks its reader whether that writer is still there (Reader::matches).
  dds_instance_handle_t publication_handle = 0;

 private:
  void release() {
    dds_sample_free(&data, Topic<T>::descriptor(), DDS_FREE_CONTENTS);
    std::memset(&data, 0, sizeof data);
  }
};

}  // namespace dynid::dds
