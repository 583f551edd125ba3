// SPDX-License-Identifier: LGPL-2.1-or-later
#include "face/animator.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace pfap::face {
namespace {

// Smooth start and end (zero slope at both) of a step from 0 to 1.
double ease(double u) {
  u = std::clamp(u, 0.0, 1.0);
  return u * u * (3 - 2 * u);
}

}  // namespace

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
  next.to = info != nullptr ? pfap::viseme_mouth(info->viseme) : generic_mouth();
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
  pfap::add_mouth(f, mouth(time_ns));
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
