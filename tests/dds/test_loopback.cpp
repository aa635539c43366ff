// Participants run on the loopback configuration only: never without an explicit one, and
// no socket of this process is bound to another interface's address.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "dds_fixture.hpp"

namespace dynid::dds {
namespace {

using namespace testing;

/// Socket inodes of this process (from /proc/self/fd).
std::set<std::string> own_socket_inodes() {
  std::set<std::string> inodes;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/fd")) {
    std::error_code error;
    const std::string target = std::filesystem::read_symlink(entry.path(), error).string();
    if (!error && target.rfind("socket:[", 0) == 0) inodes.insert(target.substr(8, target.size() - 9));
  }
  return inodes;
}

/// Local addresses (hex, as in /proc/net/udp*) of this process's sockets in `table`.
std::vector<std::string> local_addresses(const std::string& table, const std::set<std::string>& inodes) {
  std::ifstream in(table);
  std::string line;
  std::getline(in, line);  // header
  std::vector<std::string> addresses;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    std::string slot, local, remote, state, queues, timer, retransmits, uid, timeout, inode;
    fields >> slot >> local >> remote >> state >> queues >> timer >> retransmits >> uid >> timeout >> inode;
    if (inodes.count(inode)) addresses.push_back(local.substr(0, local.find(':')));
  }
  return addresses;
}

TEST(DdsLoopback, NoSocketIsBoundToAnotherInterface) {
  Participant participant(loopback_options());
  const auto inodes = own_socket_inodes();
  const auto v4 = local_addresses("/proc/self/net/udp", inodes);
  const auto v6 = local_addresses("/proc/self/net/udp6", inodes);
  const std::string loopback = "0100007F", wildcard = "00000000";  // 127.0.0.1, 0.0.0.0
  EXPECT_NE(std::count(v4.begin(), v4.end(), loopback), 0) << "no socket on 127.0.0.1";
  for (const auto& address : v4)
    EXPECT_TRUE(address == loopback || address == wildcard) << "UDP socket bound to " << address;
  EXPECT_TRUE(v6.empty()) << "IPv6 UDP socket opened";
}

TEST(DdsLoopback, AParticipantNeedsAnExplicitConfiguration) {
  EXPECT_THROW(Participant(ParticipantOptions{kDomain, ""}), DdsError);
  EXPECT_THROW(config_file_uri("/nonexistent/loopback.xml"), DdsError);
  Participant first(loopback_options());
  // The domain already runs with the loopback config: another config is refused, not ignored.
  EXPECT_THROW(Participant(ParticipantOptions{kDomain, loopback_config("other-tag")}), DdsError);
  Participant second(loopback_options());
  EXPECT_EQ(second.domain_id(), kDomain);
}

}  // namespace
}  // namespace dynid::dds
