// The option names: every value round-trips, parsing ignores case, and a bad name is an InputError
// that lists the valid names.
#include <gtest/gtest.h>

#include <cctype>
#include <string>

#include "clothcd/core/error.hpp"
#include "clothcd/detect/names.hpp"

namespace clothcd {
namespace {

std::string upper(std::string_view s) {
  std::string u(s);
  for (char& c : u)
    c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return u;
}

TEST(Names, EveryValueRoundTripsInAnyCase) {
  for (ConePolicy p :
       {ConePolicy::Provot, ConePolicy::Proposed, ConePolicy::Exact, ConePolicy::Optimal}) {
    EXPECT_EQ(parse_cone_policy(to_string(p)), p);
    EXPECT_EQ(parse_cone_policy(upper(to_string(p))), p);
  }
  for (Culling c : {Culling::None, Culling::Cone, Culling::Gated, Culling::Sound}) {
    EXPECT_EQ(parse_culling(to_string(c)), c);
    EXPECT_EQ(parse_culling(upper(to_string(c))), c);
  }
  for (BvhBuild b : {BvhBuild::Spatial, BvhBuild::Patch}) {
    EXPECT_EQ(parse_bvh_build(to_string(b)), b);
    EXPECT_EQ(parse_bvh_build(upper(to_string(b))), b);
  }
}

TEST(Names, NamesAreDistinctAndLowerCase) {
  const std::string_view names[] = {to_string(ConePolicy::Provot), to_string(ConePolicy::Proposed),
                                    to_string(ConePolicy::Exact), to_string(ConePolicy::Optimal)};
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
    EXPECT_EQ(std::string(e.what()),
              "--culling: unknown value 'fast' (one of none, cone, gated, sound)");
  }
  EXPECT_THROW((void)parse_cone_policy(""), InputError);
  EXPECT_THROW((void)parse_bvh_build("spatial "), InputError);
}

}  // namespace
}  // namespace clothcd
