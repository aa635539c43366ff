// The protocol table both ends share (wire/include/dynid/dds/protocol.hpp) and the server's
// request check built on it (server/request_parser.hpp): every kind in the table is accepted
// with its required arguments, every argument the table does not list is refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>

#include "dynid/dds/protocol.hpp"
#include "dynid/error.hpp"
#include "dynid/server/request_parser.hpp"

namespace dynid::dds::protocol {
namespace {

Request request_of(const RequestKind& kind) {
  Request r{"tester", 1, kind.name, {}};
  for (const auto& name : kind.required)
    r.arguments.push_back({name, name == "vehicles" ? "car-a,car-b" : "x"});
  return r;
}

TEST(Protocol, EveryKindIsAcceptedWithItsRequiredArguments) {
  ASSERT_FALSE(request_kinds().empty());
  for (const RequestKind& kind : request_kinds()) {
    const server::ParsedRequest parsed = server::parse_request(request_of(kind));
    EXPECT_EQ(parsed.kind, kind.name);
    for (const auto& name : kind.required)
      EXPECT_TRUE(parsed.optional(name).has_value()) << kind.name;
  }
}

TEST(Protocol, EveryOptionalArgumentIsAcceptedAndNoOtherOne) {
  for (const RequestKind& kind : request_kinds()) {
    for (const auto& name : kind.optional) {
      Request r = request_of(kind);
      r.arguments.push_back({name, name == "format" ? "json" : "1"});
      EXPECT_NO_THROW(server::parse_request(r)) << kind.name << " " << name;
    }
    Request r = request_of(kind);
    r.arguments.push_back({"no-such-argument", "1"});
    try {
      server::parse_request(r);
      ADD_FAILURE() << kind.name << " took an argument its table does not list";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("takes no argument 'no-such-argument'"),
                std::string::npos)
          << e.what();
    }
  }
}

TEST(Protocol, OnlyRepeatableArgumentsMayComeTwice) {
  for (const RequestKind& kind : request_kinds()) {
    for (const auto& name : kind.required) {
      if (name == "vehicles") continue;
      Request r = request_of(kind);
      r.arguments.push_back({name, "y"});
      if (kind.is_repeatable(name))
        EXPECT_NO_THROW(server::parse_request(r)) << kind.name << " " << name;
      else
        EXPECT_THROW(server::parse_request(r), InputError) << kind.name << " " << name;
    }
  }
}

TEST(Protocol, HtmlOnlyWhereTheKindAnswersWithAPage) {
  for (const RequestKind& kind : request_kinds()) {
    if (!kind.takes("format")) continue;
    Request r = request_of(kind);
    r.arguments.push_back({"format", "html"});
    if (kind.html_reply)
      EXPECT_NO_THROW(server::parse_request(r)) << kind.name;
    else
      EXPECT_THROW(server::parse_request(r), InputError) << kind.name;
  }
}

TEST(Protocol, KindsAreSortedAndUniqueAndUnknownOnesAreRefusedWithTheList) {
  const auto& kinds = request_kinds();
  EXPECT_TRUE(
      std::is_sorted(kinds.begin(), kinds.end(),
                     [](const RequestKind& a, const RequestKind& b) { return a.name < b.name; }));
  std::set<std::string> names;
  for (const auto& kind : kinds) EXPECT_TRUE(names.insert(kind.name).second) << kind.name;
  EXPECT_EQ(find_request_kind("no-such-kind"), nullptr);
  try {
    server::parse_request({"tester", 2, "no-such-kind", {}});
    ADD_FAILURE() << "an unknown kind was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("(known: " + request_kind_names() + ")"),
              std::string::npos)
        << e.what();
  }
}

TEST(Protocol, ServerCountersHaveUniqueNamesAndAMeaning) {
  std::set<std::string> names;
  for (const Counter& counter : kServerCounters) {
    EXPECT_TRUE(names.insert(counter.name).second) << counter.name;
    EXPECT_GT(std::string(counter.meaning).size(), 0u) << counter.name;
  }
  EXPECT_EQ(kAnnouncementSequence, ~std::uint64_t{0});
  EXPECT_EQ(kMaxRejections, std::size_t{dynid_wire_kMaxRejections});
}

}  // namespace
}  // namespace dynid::dds::protocol
