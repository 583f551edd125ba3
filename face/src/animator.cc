// SPDX-License-Identifier: LGPL-2.1-or-later
#include "face/animator.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace pfap::face {
namespace {

using pfap::Viseme;

// Smooth start and end (zero slope at both) of a step from 0 to 1.
double ease(double u) {
  u = std::clamp(u, 0.0, 1.0);
  return u * u * (3 - 2 * u);
}

}  // namespace

MouthShape MouthShape::blend(const MouthShape& to, double u) const {
  auto mix = [u](double a, double b) { return a + (b - a) * u; };
  return {mix(open_jaw, to.open_jaw),
          mix(lower_t_midlip, to.lower_t_midlip),
          mix(raise_b_midlip, to.raise_b_midlip),
          mix(stretch_corner, to.stretch_corner),
          mix(raise_corner, to.raise_corner),
          mix(push_lip, to.push_lip)};
}

MouthShape viseme_shape(Viseme viseme) {
  // {open_jaw, lower_t_midlip, raise_b_midlip, stretch_corner, raise_corner, push_lip}
  switch (viseme) {
    case Viseme::kNone:
      return {};
    case Viseme::kPBM:
      return {0, 30, 30, 0, 0, 40};
    case Viseme::kFV:
      return {70, -40, 110, 0, 0, 0};
    case Viseme::kTH:
      return {150, -20, 0, 20, 0, 0};
    case Viseme::kTD:
      return {130, 0, 0, 40, 0, 0};
    case Viseme::kKG:
      return {190, 0, 0, 30, 0, 0};
    case Viseme::kCh:
      return {110, 0, 0, -160, 0, 180};
    case Viseme::kSZ:
      return {50, -30, 0, 90, 20, 0};
    case Viseme::kNL:
      return {160, 0, 0, 30, 0, 0};
    case Viseme::kR:
      return {120, 0, 0, -110, 0, 120};
    case Viseme::kA:
      return {430, -20, 0, 40, 0, 0};
    case Viseme::kE:
      return {290, -20, 0, 130, 20, 0};
    case Viseme::kI:
      return {170, -20, 0, 200, 50, 0};
    case Viseme::kQ:
      return {380, 0, 0, -150, 0, 120};
    case Viseme::kU:
      return {120, 0, 0, -230, 0, 240};
  }
  return {};
}

MouthShape generic_mouth() { return {250, 0, 0, 40, 0, 0}; }

bool Animator::apply(const pfap::MarkupEvent& event, int64_t time_ns) {
  time_ns = std::max(time_ns, last_ns_);
  last_ns_ = time_ns;
  pfap::apply_markup(event, time_ns, state_);
  for (const pfap::Fap& fap : event.faps) {
    end_ns_ = std::max(end_ns_, time_ns + int64_t{fap.transition_ms} * pfap::kNsPerMs);
  }
  if (event.kind != PFAP_EVENT_PHONEME) return true;

  const pfap::PhonemeInfo* info =
      alphabet_ != nullptr ? pfap::find_phoneme(*alphabet_, event.phoneme.symbol) : nullptr;
  Sound next;
  next.from = mouth(time_ns);
  next.generic = info == nullptr;
  next.to = info != nullptr ? viseme_shape(info->viseme) : generic_mouth();
  next.start_ns = time_ns;
  next.end_ns = time_ns + int64_t{event.phoneme.duration_ms} * pfap::kNsPerMs;
  next.name =
      info != nullptr ? std::string(info->name) : "#" + std::to_string(event.phoneme.symbol);
  sound_ = std::move(next);
  end_ns_ = std::max(end_ns_, sound_.end_ns);
  return info != nullptr;
}

MouthShape Animator::mouth(int64_t time_ns) const {
  const Sound& s = sound_;
  const int64_t length = s.end_ns - s.start_ns;
  // The shape during the phoneme, at `t` in [start, end].
  auto during = [&](int64_t t) {
    const int64_t span = std::min(kMouthEaseNs, length / 2);
    const double u = span > 0 ? ease(static_cast<double>(t - s.start_ns) / span) : 1.0;
    MouthShape target = s.to;
    if (s.generic) {
      // Open and close once over the phoneme.
      const double x = length > 0 ? static_cast<double>(t - s.start_ns) / length : 1.0;
      target = MouthShape{}.blend(s.to, std::sin(std::numbers::pi * std::clamp(x, 0.0, 1.0)));
    }
    return s.from.blend(target, u);
  };
  if (time_ns < s.end_ns) return during(std::max(time_ns, s.start_ns));
  // A pause: the mouth closes.
  const double u = ease(static_cast<double>(time_ns - s.end_ns) / kMouthEaseNs);
  return during(s.end_ns).blend(MouthShape{}, u);
}

FapValues Animator::faps(int64_t time_ns) const {
  FapValues f{};
  for (int i = pfap::kMinFapIndex; i <= pfap::kMaxFapIndex; ++i) {
    f[i] = state_.amplitude(i, time_ns);
  }
  // The mouth adds to the lip FAPs, inner and outer; the points beside the middle move less.
  const MouthShape m = mouth(time_ns);
  f[3] += m.open_jaw;
  f[4] += m.lower_t_midlip;
  f[8] += 0.7 * m.lower_t_midlip;
  f[9] += 0.7 * m.lower_t_midlip;
  f[5] += m.raise_b_midlip;
  f[10] += 0.7 * m.raise_b_midlip;
  f[11] += 0.7 * m.raise_b_midlip;
  for (int i : {6, 7, 53, 54}) f[i] += m.stretch_corner;
  for (int i : {12, 13, 59, 60}) f[i] += m.raise_corner;
  f[16] += m.push_lip;
  f[17] += m.push_lip;
  add_expressions(f);
  return f;
}

std::string Animator::describe(int64_t time_ns) const {
  std::string text =
      time_ns >= sound_.start_ns && time_ns < sound_.end_ns ? sound_.name : std::string("pause");
  for (int i = pfap::kMinFapIndex; i <= pfap::kMaxFapIndex; ++i) {
    const long amplitude = std::lround(state_.amplitude(i, time_ns));
    if (amplitude != 0) text += " " + std::to_string(i) + ":" + std::to_string(amplitude);
  }
  return text;
}

void Animator::reset() {
  state_.reset();
  sound_ = Sound{};
  last_ns_ = 0;
  end_ns_ = 0;
}

}  // namespace pfap::face
