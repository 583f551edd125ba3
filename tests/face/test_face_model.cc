// SPDX-License-Identifier: LGPL-2.1-or-later
// The face's geometry: each FAP group moves its feature the right way, by its FAP units.
#include <gtest/gtest.h>

#include <cmath>

#include "face/model.h"

namespace pfap::face {
namespace {

FacePose pose_with(std::initializer_list<std::pair<int, double>> amplitudes) {
  FapValues f{};
  for (auto [index, amplitude] : amplitudes) f[index] = amplitude;
  add_expressions(f);
  return pose_from_faps(f);
}

double mouth_opening(const FacePose& pose) { return pose.inner_lips[6].y - pose.inner_lips[2].y; }

TEST(FaceModel, NeutralMouthIsClosedAndEyesOpen) {
  const FacePose pose = pose_with({});
  EXPECT_DOUBLE_EQ(mouth_opening(pose), 0);
  for (const Eye& eye : pose.eyes) {
    EXPECT_NEAR(eye.lower_lid - eye.upper_lid, kUnits.irisd, 1e-12);
  }
  // Symmetric about the vertical axis.
  EXPECT_NEAR(pose.eyes[kLeft].center.x, -pose.eyes[kRight].center.x, 1e-12);
  EXPECT_GT(pose.eyes[kLeft].center.x, 0) << "the face's left is the viewer's right";
}

TEST(FaceModel, OpenJawMovesTheLowerLipByMouthNoseUnits) {
  const FacePose closed = pose_with({});
  const FacePose open = pose_with({{3, 1024}});
  // A head facing the camera: the projection keeps vertical distances.
  EXPECT_NEAR(open.inner_lips[6].y - closed.inner_lips[6].y, kUnits.mns, 1e-9);
  EXPECT_NEAR(open.jaw_open, kUnits.mns, 1e-12);
  EXPECT_GT(open.outline[6].y, closed.outline[6].y) << "the chin drops";
}

TEST(FaceModel, LipFapsMoveTheirPoints) {
  const FacePose neutral = pose_with({});
  EXPECT_GT(pose_with({{4, 200}}).inner_lips[2].y, neutral.inner_lips[2].y);  // top down
  EXPECT_LT(pose_with({{3, 400}, {5, 200}}).inner_lips[6].y,
            pose_with({{3, 400}}).inner_lips[6].y);  // bottom up
  EXPECT_NEAR(pose_with({{6, 1024}}).inner_lips[4].x - neutral.inner_lips[4].x, kUnits.mw,
              0.02);                                                            // left out
  EXPECT_LT(pose_with({{7, 300}}).inner_lips[0].x, neutral.inner_lips[0].x);    // right out
  EXPECT_LT(pose_with({{12, 300}}).inner_lips[4].y, neutral.inner_lips[4].y);   // corner up
  EXPECT_LT(pose_with({{51, -300}}).outer_lips[2].y, neutral.outer_lips[2].y);  // outer top up
  EXPECT_LT(pose_with({{59, 300}}).outer_lips[4].y, neutral.outer_lips[4].y);   // outer corner
  EXPECT_LT(pose_with({{16, 300}}).outer_lips[6].y - neutral.outer_lips[6].y, 0.1);
  EXPECT_GT(pose_with({{16, 300}}).outer_lips[6].y, neutral.outer_lips[6].y);  // thicker lip
  EXPECT_LT(pose_with({{15, 500}}).outline[6].x, neutral.outline[6].x);        // jaw right
  EXPECT_LT(pose_with({{18, 300}}).outline[6].y, neutral.outline[6].y);        // chin up
}

TEST(FaceModel, LipsDoNotPassThroughEachOther) {
  const FacePose pressed = pose_with({{5, 400}});
  for (int i = 5; i <= 7; ++i) EXPECT_GE(pressed.inner_lips[i].y, pressed.inner_lips[8 - i].y);
}

TEST(FaceModel, EyelidsCloseByIrisDiameters) {
  const FacePose half = pose_with({{19, 512}});
  EXPECT_NEAR(half.eyes[kLeft].upper_lid, 0, 1e-12);
  EXPECT_NEAR(half.eyes[kRight].upper_lid, -kUnits.irisd / 2, 1e-12) << "only the left";
  const FacePose blink = pose_with({{19, 1024}, {20, 1024}, {21, 512}, {22, 512}});
  for (const Eye& eye : blink.eyes) EXPECT_DOUBLE_EQ(eye.upper_lid, eye.lower_lid);
  const FacePose wide = pose_with({{19, -300}});
  EXPECT_LT(wide.eyes[kLeft].upper_lid, -kUnits.irisd / 2);
}

TEST(FaceModel, EyeballsTurnInAngleUnits) {
  const FacePose look = pose_with({{23, 30000}, {25, 20000}});
  EXPECT_NEAR(look.eyes[kLeft].pupil.x, 0.06 * std::sin(0.3), 1e-12);
  EXPECT_GT(look.eyes[kLeft].pupil.y, 0) << "positive pitch looks down";
  EXPECT_DOUBLE_EQ(look.eyes[kRight].pupil.x, 0);
}

TEST(FaceModel, BrowsRiseAndSqueeze) {
  const FacePose neutral = pose_with({});
  const FacePose raised = pose_with({{31, 1024}, {33, 512}, {35, 256}});
  EXPECT_NEAR(neutral.brows[kLeft].points[0].y - raised.brows[kLeft].points[0].y, kUnits.ens, 1e-3);
  EXPECT_GT(neutral.brows[kLeft].points[1].y, raised.brows[kLeft].points[1].y);
  EXPECT_NEAR(raised.brows[kRight].points[0].y, neutral.brows[kRight].points[0].y, 1e-12);
  const FacePose squeezed = pose_with({{37, 300}, {38, 300}});
  EXPECT_LT(squeezed.brows[kLeft].points[0].x, neutral.brows[kLeft].points[0].x);
  EXPECT_GT(squeezed.brows[kRight].points[0].x, neutral.brows[kRight].points[0].x);
}

TEST(FaceModel, CheeksPuffAndLift) {
  const FacePose neutral = pose_with({});
  const FacePose puffed = pose_with({{39, 400}});
  EXPECT_NEAR(puffed.cheek_puff[kLeft], 400 * kUnits.es / 1024, 1e-12);
  EXPECT_GT(puffed.outline[4].x, neutral.outline[4].x);
  const FacePose lifted = pose_with({{42, 400}});
  EXPECT_LT(lifted.cheeks[kRight].y, neutral.cheeks[kRight].y);
  EXPECT_LT(lifted.eyes[kRight].lower_lid, neutral.eyes[kRight].lower_lid);
}

TEST(FaceModel, HeadYawMovesEyeCentersAndNose) {
  const FacePose neutral = pose_with({});
  const FacePose left = pose_with({{49, 30000}});  // 0.3 rad towards the face's left
  for (int side : {kLeft, kRight}) {
    EXPECT_GT(left.eyes[side].center.x, neutral.eyes[side].center.x + 0.05);
  }
  EXPECT_GT(left.nose.x, 0.1);
  // The eye turning away is foreshortened, the other widens.
  EXPECT_LT(left.eyes[kLeft].half_width, neutral.eyes[kLeft].half_width);
  EXPECT_GT(left.eyes[kRight].half_width, neutral.eyes[kRight].half_width);
  const FacePose right = pose_with({{49, -30000}});
  EXPECT_NEAR(right.nose.x, -left.nose.x, 1e-12);
}

TEST(FaceModel, HeadPitchAndRoll) {
  const FacePose neutral = pose_with({});
  EXPECT_GT(pose_with({{48, 20000}}).nose.y, neutral.nose.y) << "a nod moves the face down";
  const FacePose tilted = pose_with({{50, 20000}});
  // Rolled to the face's right (the viewer's left): the top of the head goes left.
  EXPECT_LT(tilted.outline[0].x, neutral.outline[0].x);
  EXPECT_GT(tilted.eyes[kRight].center.y, tilted.eyes[kLeft].center.y)
      << "the right side goes down";
  EXPECT_NEAR(tilted.roll, 0.2, 1e-12);
}

TEST(FaceModel, ExpressionWeightIsIntensityOver63) {
  FapValues f{};
  f[69] = 63;
  f[70] = 21;
  f[71] = 200;
  f[72] = -10;
  EXPECT_DOUBLE_EQ(expression_weight(f, 1), 1);
  EXPECT_DOUBLE_EQ(expression_weight(f, 2), 1.0 / 3);
  EXPECT_DOUBLE_EQ(expression_weight(f, 3), 1);
  EXPECT_DOUBLE_EQ(expression_weight(f, 4), 0);
}

TEST(FaceModel, ExpressionsMoveTheFace) {
  const FacePose neutral = pose_with({});
  const FacePose joy = pose_with({{69, 63}});
  EXPECT_LT(joy.inner_lips[4].y, neutral.inner_lips[4].y) << "joy lifts the corners";
  EXPECT_GT(pose_with({{70, 63}}).inner_lips[4].y, neutral.inner_lips[4].y) << "sadness";
  EXPECT_GT(pose_with({{71, 63}}).brows[kLeft].points[0].y, neutral.brows[kLeft].points[0].y)
      << "anger lowers the brows";
  EXPECT_LT(pose_with({{72, 63}}).eyes[kLeft].upper_lid, neutral.eyes[kLeft].upper_lid)
      << "fear opens the eyes";
  EXPECT_LT(pose_with({{73, 63}}).inner_lips[2].y, neutral.inner_lips[2].y)
      << "disgust raises the upper lip";
  const FacePose surprise = pose_with({{74, 63}});
  EXPECT_GT(surprise.jaw_open, 0.04);
  EXPECT_LT(surprise.brows[kRight].points[1].y, neutral.brows[kRight].points[1].y - 0.04);
  EXPECT_DOUBLE_EQ(surprise.expressions[5], 1);
}

}  // namespace
}  // namespace pfap::face
