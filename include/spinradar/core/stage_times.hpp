#pragma once
// Per-stage wall times of one scan through the pipeline, in milliseconds.
namespace spinradar {

struct StageTimes {
  double detect_ms = 0;
  double cartesian_ms = 0;
  double describe_ms = 0;
  double match_ms = 0;
  double estimate_ms = 0;
  double total() const { return detect_ms + cartesian_ms + describe_ms + match_ms + estimate_ms; }
  StageTimes& operator+=(const StageTimes& o) {
    detect_ms += o.detect_ms;
    cartesian_ms += o.cartesian_ms;
    describe_ms += o.describe_ms;
    match_ms += o.match_ms;
    estimate_ms += o.estimate_ms;
    return *this;
  }
};

}  // namespace spinradar
