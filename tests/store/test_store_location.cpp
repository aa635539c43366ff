// Store locations (location.hpp): which backend a location selects, and how messages show it.
#include <gtest/gtest.h>

#include "dynid/store/location.hpp"

namespace dynid::store {
namespace {

TEST(StoreLocation, PostgresUrisAreToldFromFilePaths) {
  EXPECT_TRUE(is_postgres_uri("postgresql://dynid@127.0.0.1:5432/fleet"));
  EXPECT_TRUE(is_postgres_uri("postgres://db/fleet"));
  EXPECT_FALSE(is_postgres_uri("/var/lib/dynid/store.db"));
  EXPECT_FALSE(is_postgres_uri("store.db"));
  EXPECT_FALSE(is_postgres_uri("postgresql.db"));
}

TEST(StoreLocation, MessagesNeverShowAPassword) {
  EXPECT_EQ(for_messages("postgresql://dynid:s3cret@db:5432/fleet?sslmode=require"),
            "postgresql://dynid:***@db:5432/fleet?sslmode=require");
  EXPECT_EQ(for_messages("postgresql://dynid@db/fleet"), "postgresql://dynid@db/fleet");
  EXPECT_EQ(for_messages("postgresql://db/fleet?user=a@b"), "postgresql://db/fleet?user=a@b");
  EXPECT_EQ(for_messages("/tmp/a:b@c.db"), "/tmp/a:b@c.db");
}

}  // namespace
}  // namespace dynid::store
