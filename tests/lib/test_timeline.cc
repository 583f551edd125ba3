// SPDX-License-Identifier: LGPL-2.1-or-later
// pfap::EventTimeline: where an event without a time starts, and events that go back.
#include "pfap/timeline.h"

#include <gtest/gtest.h>

namespace pfap {
namespace {

TEST(EventTimeline, EventWithoutTimeStartsWhereThePreviousEnded) {
  EventTimeline timeline;
  EXPECT_EQ(timeline.start(std::nullopt, 500), 500);  // the first: where the caller says
  EXPECT_EQ(timeline.start(70, 500), 70);
  timeline.add(70, 30);
  EXPECT_EQ(timeline.start(std::nullopt, 500), 100);
  timeline.add(100, 0);  // a state event lasts nothing
  EXPECT_EQ(timeline.start(std::nullopt, 500), 100);
  timeline.reset();
  EXPECT_EQ(timeline.start(std::nullopt, 500), 500);
}

TEST(EventTimeline, EarlierEventsAreFoundAndCounted) {
  EventTimeline timeline;
  EXPECT_FALSE(timeline.earlier(-5));  // nothing before the first event
  timeline.add(100, 10);
  EXPECT_FALSE(timeline.earlier(100));  // the same time does not go back
  EXPECT_TRUE(timeline.earlier(99));
  EXPECT_EQ(timeline.previous_ns(), 100);
  EXPECT_TRUE(timeline.earlier(0));
  EXPECT_EQ(timeline.earlier_count(), 2u);
  timeline.reset();  // a new stream: nothing to go back from, the count stays
  EXPECT_FALSE(timeline.earlier(0));
  EXPECT_EQ(timeline.earlier_count(), 2u);
}

}  // namespace
}  // namespace pfap
