// The command arbiter on its own: the highest behaviour on the priority list wins, whatever
// the order of the proposals; a speed cap applies to the winner only.
#include <gtest/gtest.h>

#include "sketchnav/nav/command_arbiter.h"

using namespace sketchnav;
using namespace sketchnav::nav;

TEST(CommandArbiter, ThePriorityListIsExplicitAndComplete) {
  const auto& p = CommandArbiter::priority();
  const std::vector<std::string> names = {"final_look", "yield", "recover", "dock", "side_look",
                                          "detour",     "avoid", "servo",   "look", "follow"};
  ASSERT_EQ(p.size(), names.size());
  for (size_t i = 0; i < p.size(); ++i) EXPECT_EQ(toString(p[i]), names[i]) << i;
  EXPECT_EQ(modeOf(Behaviour::FinalLook), Mode::Look);
  EXPECT_EQ(modeOf(Behaviour::Look), Mode::Look);
  EXPECT_EQ(modeOf(Behaviour::Yield), Mode::Yield);
  EXPECT_EQ(modeOf(Behaviour::Follow), Mode::Follow);
  EXPECT_STREQ(toString(modeOf(Behaviour::Detour)), "detour");
}

TEST(CommandArbiter, TheHighestProposalWinsWhateverTheOrder) {
  const auto& p = CommandArbiter::priority();
  // Every pair, proposed both ways round: the one earlier in the list wins.
  for (size_t hi = 0; hi < p.size(); ++hi)
    for (size_t lo = hi + 1; lo < p.size(); ++lo)
      for (int order = 0; order < 2; ++order) {
        CommandArbiter a;
        const Command ch{0.1 * hi, 0.2, servo::Turn::Left};
        const Command cl{0.1 * lo, -0.2, servo::Turn::Right};
        if (order == 0) {
          a.propose(p[hi], ch);
          a.propose(p[lo], cl);
        } else {
          a.propose(p[lo], cl);
          a.propose(p[hi], ch);
        }
        EXPECT_EQ(a.winning(), p[hi]) << toString(p[hi]) << " vs " << toString(p[lo]);
        EXPECT_EQ(a.winner().v, ch.v);
        EXPECT_EQ(a.winner().turn, servo::Turn::Left);
      }
}

TEST(CommandArbiter, ASpeedCapAppliesToTheWinnerOnly) {
  CommandArbiter a;
  EXPECT_FALSE(a.any());
  EXPECT_EQ(a.winner().v, 0.0);  // nothing proposed: a zero command
  a.setWinnerSpeed(0.5);         // and nothing to cap
  EXPECT_EQ(a.winner().v, 0.0);
  a.propose(Behaviour::Follow, {0.3, 0.1, servo::Turn::Left});
  a.propose(Behaviour::Dock, {0.25, -0.1, servo::Turn::Right});
  a.setWinnerSpeed(0.1);
  EXPECT_EQ(a.winning(), Behaviour::Dock);
  EXPECT_EQ(a.winner().v, 0.1);
  EXPECT_EQ(a.winner().w, -0.1);
  // A re-proposal replaces the behaviour's earlier one; clear() forgets them all.
  a.propose(Behaviour::Dock, {0.2, 0.0, servo::Turn::Straight});
  EXPECT_EQ(a.winner().v, 0.2);
  a.clear();
  EXPECT_FALSE(a.proposed(Behaviour::Dock));
  EXPECT_FALSE(a.any());
  a.propose(Behaviour::Follow, {0.3, 0.1, servo::Turn::Left});
  EXPECT_EQ(a.winner().v, 0.3);  // Follow's own value, not capped by the earlier call
}
