// Two processes over the loopback interface: chunks go to dds_echo (a separate process), come
// back bit for bit, and its acks arrive. This is the path a car and the server take.
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <thread>

#include "dds_fixture.hpp"
#include "dynid/dds/conversions.hpp"
#include "dynid/dds/writer.hpp"

extern char** environ;

namespace dynid::dds {
namespace {

using namespace testing;

/// Waits for our child `pid` up to `timeout`; kills it (by its id) if it is still running.
int wait_child(pid_t pid, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  int status = 0;
  while (waitpid(pid, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      return -1;
    }
    std::this_thread::sleep_for(20ms);
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(DdsCrossProcess, ChunksEchoBitForBitAndAcksArrive) {
  const std::string tag = process_tag() + "-echo";
  const std::size_t count = 3;
  std::string program = DDS_ECHO, count_text = std::to_string(count);
  char* argv[] = {program.data(), const_cast<char*>(tag.c_str()), count_text.data(), nullptr};
  pid_t pid = 0;
  ASSERT_EQ(posix_spawn(&pid, program.c_str(), nullptr, nullptr, argv, environ), 0);

  int exit_code = -1;
  {
    Participant car(loopback_options(tag));
    Writer<dynid_wire_Chunk> writer(car, {vehicle_partition("echo-in")});
    Reader<dynid_wire_Chunk> echoed(car, {vehicle_partition("echo-out")});
    Reader<dynid_wire_ChunkAck> acks(car, {vehicle_partition("echo-in")});
    ASSERT_TRUE(writer.wait_for_readers(1, kPatience)) << "dds_echo not discovered";
    ASSERT_TRUE(echoed.wait_for_writers(1, kPatience));

    std::vector<ingest::Chunk> sent;
    for (std::uint64_t s = 0; s < count; ++s) {
      sent.push_back(make_chunk("echo-in", "run-9", s, 3000, 1));  // 72 kB: several datagrams
      ASSERT_TRUE(writer.write(to_wire(sent.back()).data));
    }
    auto back = take_count(echoed, count);
    ASSERT_EQ(back.size(), count);
    for (std::size_t k = 0; k < count; ++k) {
      const auto got = from_wire(back[k].data);
      EXPECT_EQ(got.sequence, sent[k].sequence);
      EXPECT_EQ(got.valid, sent[k].valid);
      EXPECT_EQ(got.checksum, sent[k].checksum);
      EXPECT_TRUE(same_bits(got.samples, sent[k].samples)) << "chunk " << k;
    }
    std::int64_t highest = -1;
    const auto deadline = std::chrono::steady_clock::now() + kPatience;
    while (highest < 2 && std::chrono::steady_clock::now() < deadline)
      for (const auto& sample : acks.wait_take(100ms)) highest = from_wire(sample.data).highest_contiguous;
    EXPECT_EQ(highest, 2);
    exit_code = wait_child(pid, kPatience);
  }
  EXPECT_EQ(exit_code, 0);
}

}  // namespace
}  // namespace dynid::dds
