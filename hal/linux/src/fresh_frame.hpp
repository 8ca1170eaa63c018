#pragma once

#include <algorithm>
#include <cstdint>

// hal::Camera::acquire hands out the next frame: one whose exposure began after the call. The
// earliest time stamp such a frame can carry: a start-of-exposure stamp is at or after the call,
// an end-of-frame stamp (what drivers give unless they say otherwise) a frame period later.
namespace smx::lnx::detail {

[[nodiscard]] inline std::int64_t freshFrameStampNs(std::int64_t calledNs, int fps,
                                                    bool startOfExposureStamp) {
  return startOfExposureStamp ? calledNs : calledNs + 1'000'000'000 / std::max(fps, 1);
}

}  // namespace smx::lnx::detail
