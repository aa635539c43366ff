// deploy/security/make-pki.sh (label security): what it makes verifies with openssl (identity
// certificates and signed documents against the CA, subjects bound to grants, a car's grant
// limited to its partition), enrolling reuses the CA, and bad arguments are refused with a
// message naming them and change nothing.
#include <gtest/gtest.h>

#include "security_fixture.hpp"

namespace dynid::security_test {
namespace {

const std::string kTool = std::string(DYNID_SOURCE_DIR) + "/deploy/security/make-pki.sh";

Outcome make_pki(const std::vector<std::string>& arguments) {
  std::vector<std::string> argv{kTool};
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  return run(argv, 60s);
}

Outcome openssl(const std::vector<std::string>& arguments) {
  std::vector<std::string> argv{"/usr/bin/openssl"};
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  return run(argv, 30s);
}

TEST(MakePki, IssuesVerifiableIdentitiesAndGrantsAndEnrolsWithTheSameCa) {
  const TempDir dir;
  const auto out = dir.path() / "pki";
  const auto made = make_pki({"--out", out.string(), "--days", "1", "--server", "main", "--car", "A",
                              "--engineer", "alice"});
  ASSERT_EQ(made.exit_code, 0) << made.output;
  const std::string ca = (out / "ca" / "ca_cert.pem").string();
  for (const std::string subject : {"server-main", "car-A", "engineer-alice"}) {
    const auto verified = openssl({"verify", "-CAfile", ca, (out / subject / "cert.pem").string()});
    EXPECT_EQ(verified.exit_code, 0) << subject << ": " << verified.output;
    const auto signed_by_ca = openssl({"smime", "-verify", "-in", (out / subject / "permissions.p7s").string(),
                                       "-CAfile", ca, "-out", "/dev/null"});
    EXPECT_EQ(signed_by_ca.exit_code, 0) << subject << ": " << signed_by_ca.output;
    EXPECT_NE(read_text(out / subject / "cyclonedds.xml").find("<NetworkInterface address=\"127.0.0.1\"/>"),
              std::string::npos) << subject << ": the loopback configuration is kept";
  }
  const std::string car = read_text(out / "car-A" / "permissions.xml");
  EXPECT_NE(car.find("<subject_name>CN=A,OU=car,O=dynid</subject_name>"), std::string::npos) << car;
  EXPECT_NE(car.find("<partition>vehicle/A</partition>"), std::string::npos) << car;
  EXPECT_EQ(car.find("vehicle/*"), std::string::npos) << "a car is granted its own partition only\n" << car;
  EXPECT_EQ(car.find("dynid/Estimate"), std::string::npos) << car;
  EXPECT_EQ(read_text(out / "engineer-alice" / "permissions.xml").find("dynid/Chunk<"), std::string::npos);

  const std::string ca_before = read_text(ca), car_before = read_text(out / "car-A" / "cert.pem");
  const auto enrolled = make_pki({"--out", out.string(), "--days", "1", "--car", "C"});
  ASSERT_EQ(enrolled.exit_code, 0) << enrolled.output;
  EXPECT_EQ(read_text(ca), ca_before) << "enrolling keeps the CA";
  EXPECT_EQ(openssl({"verify", "-CAfile", ca, (out / "car-C" / "cert.pem").string()}).exit_code, 0);

  const auto again = make_pki({"--out", out.string(), "--car", "A"});
  EXPECT_EQ(again.exit_code, 1);
  EXPECT_NE(again.output.find("car 'A' is already enrolled"), std::string::npos) << again.output;
  EXPECT_EQ(read_text(out / "car-A" / "cert.pem"), car_before) << "a refused enrolment changes nothing";
}

TEST(MakePki, RefusesBadArgumentsNamingThemAndWritesNothing) {
  const TempDir dir;
  const auto out = dir.path() / "pki";
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases{
      {{"--car", "A"}, "--out is required"},
      {{"--out", out.string()}, "no subject given"},
      {{"--out", out.string(), "--car", "A/B"}, "--car 'A/B': use 1 to 64 characters"},
      {{"--out", out.string(), "--car", "*"}, "--car '*'"},
      {{"--out", out.string(), "--car", "A", "--car", "A"}, "--car 'A' given twice"},
      {{"--out", out.string(), "--car", "A", "--days", "0"}, "--days '0'"},
      {{"--out", out.string(), "--car", "A", "--domains", "5-2"}, "--domains '5-2'"},
      {{"--out", out.string(), "--car", "A", "--network-config", "/nonexistent.xml"}, "no such file"},
      {{"--out", out.string(), "--car", "A", "--plugin-dir", "/tmp"}, "libdds_security_auth.so missing"},
      {{"--out", out.string(), "--car"}, "--car needs a value"},
      {{"--out", out.string(), "--truck", "A"}, "unknown argument '--truck'"},
  };
  for (const auto& [arguments, message] : cases) {
    const auto result = make_pki(arguments);
    EXPECT_EQ(result.exit_code, 1) << message;
    EXPECT_NE(result.output.find(message), std::string::npos) << "expected '" << message << "' in\n" << result.output;
    EXPECT_FALSE(std::filesystem::exists(out)) << message << ": nothing may be written";
  }
  const auto file = dir.path() / "a-file";
  std::filesystem::copy_file(std::string(DYNID_SOURCE_DIR) + "/deploy/cyclonedds/loopback.xml", file);
  const auto not_a_folder = make_pki({"--out", file.string(), "--car", "A"});
  EXPECT_EQ(not_a_folder.exit_code, 1);
  EXPECT_NE(not_a_folder.output.find("exists and is not a folder"), std::string::npos) << not_a_folder.output;
}

}  // namespace
}  // namespace dynid::security_test
