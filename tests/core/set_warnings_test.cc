// The warnings dgmm gave when it made a set, kept in its metadata.
#include "core/set_warnings.h"

#include <gtest/gtest.h>

namespace dgmm {
namespace {

TEST(SetWarnings, KeptOnePerLineAndReadBackInOrder) {
  SampleSet s;
  EXPECT_TRUE(KeptWarnings(s).empty());
  KeepWarnings({"torso tilted", "legs touched"}, &s);
  EXPECT_EQ(s.metadata.at(kSetWarningsKey), "torso tilted\nlegs touched");
  EXPECT_EQ(KeptWarnings(s), (std::vector<std::string>{"torso tilted", "legs touched"}));
  s.metadata[kSetWarningsKey] = "a\n\nb\n";
  EXPECT_EQ(KeptWarnings(s), (std::vector<std::string>{"a", "b"})) << "empty lines skipped";
  KeepWarnings({}, &s);
  EXPECT_EQ(s.metadata.count(kSetWarningsKey), 0u) << "none: no key, as in an older set";
}

}  // namespace
}  // namespace dgmm
