// dds_echo: the far end of test_cross_process, a separate process on the loopback config.
// Takes `count` chunks from partition vehicle/echo-in, converts each to the core struct and
// back, writes it to vehicle/echo-out and acknowledges it on vehicle/echo-in.
//
//   dds_echo <discovery tag> <count>
// Exit status: 0 done, 2 timeout (nothing for 10 s), 3 a chunk was rejected, 4 usage/error.
#include <iostream>
#include <thread>

#include "dds_fixture.hpp"
#include "dynid/dds/conversions.hpp"
#include "dynid/dds/writer.hpp"

int main(int argc, char** argv) {
  using namespace dynid::dds;
  if (argc != 3) {
    std::cerr << "usage: dds_echo <tag> <count>\n";
    return 4;
  }
  try {
    const std::size_t count = std::stoul(argv[2]);
    Participant participant(testing::loopback_options(argv[1]));
    Reader<dynid_wire_Chunk> in(participant, {vehicle_partition("echo-in")});
    Writer<dynid_wire_Chunk> out(participant, {vehicle_partition("echo-out")});
    Writer<dynid_wire_ChunkAck> acks(participant, {vehicle_partition("echo-in")});
    // Discovery is asymmetric: the test may see our writers before they see its readers, and a
    // volatile writer drops what it writes before a reader matches (seen under ASan's slowness).
    if (!out.wait_for_readers(1, std::chrono::seconds(10)) ||
        !acks.wait_for_readers(1, std::chrono::seconds(10)))
      return 2;
    for (std::size_t done = 0; done < count;) {
      auto samples = in.wait_take(std::chrono::seconds(10));
      if (samples.empty()) return 2;
      for (const auto& sample : samples) {
        const auto chunk = from_wire(sample.data);
        out.write(to_wire(chunk).data);
        acks.write(to_wire(ChunkReceipt{chunk.vehicle, chunk.run,
                                        static_cast<std::int64_t>(chunk.sequence), {}}).data);
        ++done;
      }
    }
    // Let the reliable protocol deliver the last samples before the writers go away.
    out.wait_for_readers(1, std::chrono::seconds(1));
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    return 0;
  } catch (const dynid::InputError& error) {
    std::cerr << "dds_echo: rejected: " << error.what() << "\n";
    return 3;
  } catch (const std::exception& error) {
    std::cerr << "dds_echo: " << error.what() << "\n";
    return 4;
  }
}
