// SocketCanSource on the machine at hand: a kernel without CAN (the build machines) must give a
// clear SocketCanError naming EAFNOSUPPORT, the call and the interface, never a crash; a kernel
// with CAN must name ENODEV for an interface that does not exist. Bad names and filters are
// rejected before any system call. The frames themselves are tested for real in the VM test
// (socketcan_vm_test.sh).
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <string>

#include <dynid/car/can_interface_follower.hpp>
#include <dynid/car/socketcan_source.hpp>
#include <dynid/car/vehicle_profile.hpp>

namespace dynid::car {
namespace {

// errno of socket(AF_CAN, SOCK_RAW, CAN_RAW) here, 0 when it works.
int can_socket_errno() {
  const int fd = ::socket(PF_CAN, SOCK_RAW, 1 /* CAN_RAW */);
  if (fd < 0) return errno;
  ::close(fd);
  return 0;
}

SocketCanError open_error(const std::string& iface, const SocketCanOptions& options = {}) {
  try {
    SocketCanSource source(iface, options);
  } catch (const SocketCanError& e) {
    return e;
  }
  ADD_FAILURE() << "opening " << iface << " did not throw";
  return SocketCanError(iface, "nothing", 0);
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(SocketCanSource, KernelWithoutCanNamesEafnosupport) {
  if (can_socket_errno() != EAFNOSUPPORT) GTEST_SKIP() << "this kernel has AF_CAN";
  const SocketCanError e = open_error("can0");
  EXPECT_EQ(e.error_number(), EAFNOSUPPORT);
  EXPECT_EQ(e.interface_name(), "can0");
  const std::string what = e.what();
  EXPECT_TRUE(contains(what, "SocketCAN can0: socket(PF_CAN, SOCK_RAW, CAN_RAW) failed")) << what;
  EXPECT_TRUE(contains(what, "(EAFNOSUPPORT)")) << what;
  EXPECT_TRUE(contains(what, "no SocketCAN support")) << what;
}

TEST(SocketCanSource, KernelWithCanNamesMissingInterface) {
  if (can_socket_errno() != 0) GTEST_SKIP() << "this kernel has no AF_CAN";
  const SocketCanError e = open_error("dynidnosuch0");
  EXPECT_EQ(e.error_number(), ENODEV);
  EXPECT_TRUE(contains(e.what(), "dynidnosuch0")) << e.what();
  EXPECT_TRUE(contains(e.what(), "(ENODEV)")) << e.what();
}

// A second bus followed live (--source chassis=IFACE) opens its interface before the run: an
// interface this kernel cannot give is the same SocketCanError, naming it, before any state.
TEST(CanInterfaceFollower, AnInterfaceThatCannotBeOpenedIsRefusedBeforeTheRun) {
  const std::string text =
      "[vehicle]\nid = \"aux-car\"\ndbc = \"" + std::string(DYNID_SOURCE_DIR) +
      "/deploy/dbc/dynid_testcar.dbc\"\n[grid]\nrate_hz = 100.0\nchunk_seconds = 1.0\n[spool]\n"
      "directory = \"spool\"\nmax_bytes = 1000000\n[[channels]]\nname = \"vx\"\nmessage = \"ESP_Dynamics\"\n"
      "signal = \"VehSpeed\"\n[[sources]]\nname = \"chassis\"\ntype = \"can\"\ndbc = \"" +
      std::string(DYNID_SOURCE_DIR) + "/deploy/dbc/dynid_testcar.dbc\"\nclock = { offset = 0.0 }\n"
      "[[sources.channels]]\nname = \"yaw_rate\"\nmessage = \"ESP_Dynamics\"\nsignal = \"YawRate\"\n";
  const VehicleProfile profile = parse_vehicle_profile(text, "aux.toml");
  try {
    CanInterfaceFollower follower(profile.sources.at(0), "dynidnosuch1", 0.0);
    ADD_FAILURE() << "opened an interface that does not exist";
  } catch (const SocketCanError& e) {
    EXPECT_EQ(e.interface_name(), "dynidnosuch1");
    EXPECT_TRUE(e.error_number() == ENODEV || e.error_number() == EAFNOSUPPORT) << e.what();
  }
}

TEST(SocketCanSource, AnyKernelGivesSocketCanErrorForAMissingInterface) {
  // Whatever the kernel says first, it is a SocketCanError that is also an InputError.
  try {
    SocketCanSource source("dynidnosuch0");
    FAIL() << "opened an interface that does not exist";
  } catch (const InputError& e) {
    EXPECT_NE(dynamic_cast<const SocketCanError*>(&e), nullptr);
    EXPECT_TRUE(contains(e.what(), "dynidnosuch0")) << e.what();
  }
}

TEST(SocketCanSource, RejectsBadNamesAndFiltersBeforeTheKernel) {
  for (const std::string bad : {"", "sixteen_chars_xx", "a/b"}) {
    try {
      SocketCanSource source(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const SocketCanError& e) {
      ADD_FAILURE() << "asked the kernel about '" << bad << "': " << e.what();
    } catch (const InputError& e) {
      EXPECT_TRUE(contains(e.what(), "bad interface name")) << e.what();
    }
  }
  SocketCanOptions options;
  options.filters.push_back(CanFilter{0x800, 0x7FF, false, false});  // 12 bits as an 11-bit id
  try {
    SocketCanSource source("can0", options);
    ADD_FAILURE() << "accepted an 11-bit filter on 0x800";
  } catch (const SocketCanError& e) {
    ADD_FAILURE() << "asked the kernel before checking the filter: " << e.what();
  } catch (const InputError& e) {
    EXPECT_TRUE(contains(e.what(), "0x800/0x7FF")) << e.what();
  }
}

TEST(SocketCanSource, ErrnoNames) {
  EXPECT_EQ(errno_name(EAFNOSUPPORT), "EAFNOSUPPORT");
  EXPECT_EQ(errno_name(ENODEV), "ENODEV");
  EXPECT_EQ(errno_name(99999), "errno 99999");
}

TEST(SocketCanDump, ReportsTheKernelErrorAndExitsOne) {
  if (can_socket_errno() != EAFNOSUPPORT) GTEST_SKIP() << "this kernel has AF_CAN";
  const std::string command = std::string(DYNID_SOCKETCAN_DUMP) + " --seconds 1 can0 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  char buffer[256];
  while (std::fgets(buffer, sizeof(buffer), pipe) != nullptr) output += buffer;
  const int status = ::pclose(pipe);
  ASSERT_TRUE(WIFEXITED(status)) << output;
  EXPECT_EQ(WEXITSTATUS(status), 1) << output;
  EXPECT_TRUE(contains(output, "SocketCAN can0")) << output;
  EXPECT_TRUE(contains(output, "(EAFNOSUPPORT)")) << output;
}

}  // namespace
}  // namespace dynid::car
