#include <gtest/gtest.h>

#include "sketchnav/core/error.h"
#include "sketchnav/core/uri.h"

using sketchnav::InputError;
using sketchnav::Uri;

TEST(Uri, ParsesPathAuthorityAndQuery) {
  const Uri u = Uri::parse("folder:///data/my%20frames?fps=12.5&loop");
  EXPECT_EQ(u.scheme, "folder");
  EXPECT_EQ(u.authority, "");
  EXPECT_EQ(u.path, "/data/my frames");
  EXPECT_DOUBLE_EQ(u.paramDouble("fps", 1), 12.5);
  EXPECT_EQ(u.paramInt("loop", 0), 1);
  EXPECT_EQ(u.param("missing", "x"), "x");
}

TEST(Uri, HostAndPort) {
  const Uri u = Uri::parse("DANI://192.168.1.20:5000");
  EXPECT_EQ(u.scheme, "dani");
  EXPECT_EQ(u.host(), "192.168.1.20");
  EXPECT_EQ(u.port(), 5000);
  EXPECT_THROW(Uri::parse("dani://host").port(), InputError);
  EXPECT_THROW(Uri::parse("dani://host:99999").port(), InputError);
}

TEST(Uri, RejectsMalformed) {
  EXPECT_THROW(Uri::parse("/just/a/path"), InputError);
  EXPECT_THROW(Uri::parse("://x"), InputError);
  EXPECT_THROW(Uri::parse("fo o://x"), InputError);
  EXPECT_THROW(Uri::parse("folder:///a%zz"), InputError);
  EXPECT_THROW(Uri::parse("sim://lab?seed=abc").paramInt("seed", 0), InputError);
}
