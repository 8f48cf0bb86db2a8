// The option names, the simulator's and the research ones: every value round-trips, parsing
// ignores case, a bad name is an InputError that lists the valid names, and the research rules
// set and read back DetectOptions.
#include <gtest/gtest.h>

#include <cctype>
#include <string>

#include "clothcd/core/error.hpp"
#include "clothcd/detect/names.hpp"
#include "clothcd/research/detector.hpp"
#include "clothcd/research/names.hpp"

namespace clothcd {
// A namespace of its own: the research types below stay in this file of the unity build.
namespace names_test {

// The research detector and options (unsound rules, optimal cones, verification).
using research::DetectOptions;
using research::SelfDetector;

std::string upper(std::string_view s) {
  std::string u(s);
  for (char& c : u)
    c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return u;
}

TEST(Names, EveryValueRoundTripsInAnyCase) {
  for (ConePolicy p : {ConePolicy::Provot, ConePolicy::Proposed, ConePolicy::Exact}) {
    EXPECT_EQ(parse_cone_policy(to_string(p)), p);
    EXPECT_EQ(parse_cone_policy(upper(to_string(p))), p);
  }
  for (Culling c : {Culling::None, Culling::Sound}) {
    EXPECT_EQ(parse_culling(to_string(c)), c);
    EXPECT_EQ(parse_culling(upper(to_string(c))), c);
  }
  for (BvhBuild b : {BvhBuild::Spatial, BvhBuild::Patch}) {
    EXPECT_EQ(parse_bvh_build(to_string(b)), b);
    EXPECT_EQ(parse_bvh_build(upper(to_string(b))), b);
  }
}

TEST(Names, NamesAreDistinctAndLowerCase) {
  using research::ConeRule;
  const std::string_view names[] = {to_string(ConePolicy::Provot), to_string(ConePolicy::Proposed),
                                    to_string(ConePolicy::Exact),
                                    research::to_string(ConeRule::Optimal)};
  for (std::size_t i = 0; i < std::size(names); ++i) {
    for (std::size_t j = i + 1; j < std::size(names); ++j)
      EXPECT_NE(names[i], names[j]);
    for (char c : names[i])
      EXPECT_TRUE(std::islower(static_cast<unsigned char>(c)));
  }
}

TEST(Names, UnknownNameListsTheValidOnes) {
  try {
    (void)parse_culling("fast", "--culling");
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "--culling: unknown value 'fast' (one of none, sound)");
  }
  // A simulator's parser refuses the research settings.
  EXPECT_THROW((void)parse_culling("cone"), InputError);
  EXPECT_THROW((void)parse_cone_policy("optimal"), InputError);
  EXPECT_THROW((void)parse_cone_policy(""), InputError);
  EXPECT_THROW((void)parse_bvh_build("spatial "), InputError);
}

// The research names: the simulator's names mean the same, plus cone, gated and optimal; each
// rule sets the options the detector reads and reads back from them.
TEST(ResearchNames, EveryRuleRoundTripsThroughNamesAndOptions) {
  using research::ConeRule;
  using research::CullingRule;
  for (CullingRule c :
       {CullingRule::None, CullingRule::Cone, CullingRule::Gated, CullingRule::Sound}) {
    SCOPED_TRACE(research::to_string(c));
    EXPECT_EQ(research::parse_culling_rule(research::to_string(c)), c);
    EXPECT_EQ(research::parse_culling_rule(upper(research::to_string(c))), c);
    DetectOptions o;
    o.culling = Culling::Sound;
    research::set_culling_rule(o, c);
    EXPECT_EQ(research::culling_rule(o), c);
    EXPECT_EQ(o.research.culling.has_value(), c == CullingRule::Cone || c == CullingRule::Gated);
    EXPECT_EQ(research::unsound(c), c == CullingRule::Cone || c == CullingRule::Gated);
  }
  for (ConeRule p : {ConeRule::Provot, ConeRule::Proposed, ConeRule::Exact, ConeRule::Optimal}) {
    SCOPED_TRACE(research::to_string(p));
    EXPECT_EQ(research::parse_cone_rule(research::to_string(p)), p);
    EXPECT_EQ(research::parse_cone_rule(upper(research::to_string(p))), p);
    DetectOptions o;
    research::set_cone_rule(o, p);
    EXPECT_EQ(research::cone_rule(o), p);
    EXPECT_EQ(o.research.optimal_cones, p == ConeRule::Optimal);
    if (p != ConeRule::Optimal) {
      EXPECT_EQ(research::to_string(p), to_string(o.policy));
    }
  }
  EXPECT_EQ(research::to_string(CullingRule::None), to_string(Culling::None));
  EXPECT_EQ(research::to_string(CullingRule::Sound), to_string(Culling::Sound));
  // The paper's names, any case.
  EXPECT_EQ(research::parse_cone_rule("PROVOT"), ConeRule::Provot);
  EXPECT_EQ(research::parse_cone_rule("PROPOSED"), ConeRule::Proposed);
  // An unsound rule overrides the culling.
  DetectOptions o;
  o.culling = Culling::Sound;
  o.research.culling = CullingRule::Gated;
  EXPECT_EQ(research::culling_rule(o), CullingRule::Gated);
  try {
    (void)research::parse_culling_rule("fast", "--culling");
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "--culling: unknown value 'fast' (one of none, cone, gated, sound)");
  }
  try {
    (void)research::parse_cone_rule("wide", "--policy");
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "--policy: unknown value 'wide' (one of provot, proposed, exact, optimal)");
  }
}

}  // namespace names_test
}  // namespace clothcd
