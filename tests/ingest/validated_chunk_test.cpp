// ValidatedChunk and RunProcessor::push(const ValidatedChunk&): a chunk validated for the run
// under the processor's limits is pushed without a second validation and gives the same bits as
// push(Chunk); one validated for another run, or under other limits, is validated again (and
// rejected if it fails, changing nothing); a bad chunk cannot become a ValidatedChunk; the
// encoding it keeps is encode_chunk's.
#include "dynid/ingest/validated_chunk.hpp"

#include "dynid/ingest/run_processor.hpp"
#include "ingest_test_support.hpp"

namespace dynid::ingest {
namespace {

using test::TestRun;

TEST(ValidatedChunk, PushedAsValidatedGivesTheSameBitsAsAPlainPush) {
  const TestRun run = test::make_run(3000);
  const std::vector<Eigen::Index> sizes = test::random_cuts(run.samples.rows(), 150, 4u);
  RunProcessor plain(run.announcement), validated(run.announcement);
  Eigen::Index first = 0;
  for (std::size_t i = 0; i < sizes.size(); ++i) {
    const Chunk c = test::cut(run, i, first, sizes[i]);
    plain.push(c);
    const ValidatedChunk v = ValidatedChunk::validate(std::make_shared<const Chunk>(c), run.announcement);
    EXPECT_TRUE(v.validated_for(run.announcement, ChunkLimits{}));
    validated.push(v);
    first += sizes[i];
  }
  plain.finish();
  validated.finish();
  EXPECT_EQ(validated.checkpoint(), plain.checkpoint());
  EXPECT_GT(validated.counters().final_samples, 0u);
}

TEST(ValidatedChunk, KeepsTheEncodingItChecked) {
  const TestRun run = test::make_run(500);
  const Chunk c = test::cut(run, 0, 0, 100);
  const std::string expected = encode_chunk(c);
  EXPECT_EQ(validate_and_encode(c, run.announcement), expected);
  EXPECT_EQ(ValidatedChunk::validate(c, run.announcement).encoded(), expected);
  EXPECT_EQ(decode_chunk(expected).checksum, c.checksum);
}

TEST(ValidatedChunk, ABadChunkCannotBeMadeOne) {
  const TestRun run = test::make_run(500);
  Chunk corrupt = test::cut(run, 0, 0, 100);
  corrupt.samples(3, 1) += 1.0;
  test::expect_input_error([&] { ValidatedChunk::validate(corrupt, run.announcement); },
                           {"#0", "checksum", "corrupted"});
  test::expect_input_error(
      [&] { ValidatedChunk::validate(std::shared_ptr<const Chunk>(), run.announcement); },
      {run.announcement.vehicle, "null"});
}

TEST(ValidatedChunk, ValidatedForAnotherRunOrOtherLimitsIsValidatedAgain) {
  const TestRun run = test::make_run(500);
  RunProcessor p(run.announcement);
  p.push(ValidatedChunk::validate(test::cut(run, 0, 0, 100), run.announcement));
  const std::string before = p.checkpoint();

  // Validated for another run of the vehicle: the processor's own check names the run.
  RunAnnouncement other = run.announcement;
  other.run = "another-run";
  Chunk foreign = test::cut(run, 1, 100, 100);
  foreign.run = other.run;
  foreign.seal();
  const ValidatedChunk v = ValidatedChunk::validate(foreign, other);
  EXPECT_FALSE(v.validated_for(run.announcement, ChunkLimits{}));
  test::expect_input_error([&] { p.push(v); }, {"#1", "run 'another-run'"});

  // Validated under laxer limits than the processor's: its own limits decide.
  Chunk big = test::cut(run, 1, 100, 100);
  big.samples(2, 0) = 1e16;
  big.seal();
  ChunkLimits lax;
  lax.max_abs_value = 1e17;
  const ValidatedChunk w = ValidatedChunk::validate(big, run.announcement, lax);
  EXPECT_FALSE(w.validated_for(run.announcement, ChunkLimits{}));
  test::expect_input_error([&] { p.push(w); }, {"#1", "exceeds the limit"});
  EXPECT_EQ(p.checkpoint(), before);

  p.push(ValidatedChunk::validate(test::cut(run, 1, 100, 100), run.announcement));
  EXPECT_EQ(p.next_sequence(), 2u);
}

}  // namespace
}  // namespace dynid::ingest
