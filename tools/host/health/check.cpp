#include "smx/health/check.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <sstream>

#include "smx/health/attribution.hpp"
#include "smx/health/camera_depths.hpp"
#include "smx/health/cross_camera.hpp"

namespace smx::health {

namespace {

DisagreementField projectorPairField(const CameraDepths& d, int p, int q) {
  DisagreementField field{d.width, d.height, std::vector<double>(d.depth[0].size())};
  const auto& zp = d.depth[static_cast<std::size_t>(p)];
  const auto& zq = d.depth[static_cast<std::size_t>(q)];
  for (std::size_t i = 0; i < field.mm.size(); ++i) {
    field.mm[i] =
        zp[i] == algo::kNoDepth || zq[i] == algo::kNoDepth
            ? std::numeric_limits<double>::quiet_NaN()
            : atReferenceDistance((static_cast<double>(zp[i]) - zq[i]) * d.depthUnitM * 1000.0,
                                  0.5 * (zp[i] + zq[i]) * d.depthUnitM);
  }
  return field;
}

std::string fixed(double v) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(2);
  s << v;
  return s.str();
}

bool involves(const Comparison& c, int p) {
  return c.projector == p || (c.kind == Comparison::Kind::kProjectorPair && c.otherProjector == p);
}

int partner(const Comparison& c, int p) {
  return c.projector == p ? c.otherProjector : c.projector;
}

// Verdicts from the comparisons (docs/health-check.md, "What can be named").
struct Judge {
  const algo::Rig& rig;
  std::vector<Comparison>& comparisons;
  std::vector<ProjectorHealth> out;

  [[nodiscard]] const std::string& id(int p) const {
    return rig.projectors[static_cast<std::size_t>(p)].id;
  }

  void note(int p, const Comparison& c) {
    auto& h = out[static_cast<std::size_t>(p)];
    h.disagreementMm = std::max(h.disagreementMm, c.disagreement.systematicMm);
  }

  // A projector with a second camera: its own stripes seen twice decide.
  bool byCameras(int p) {
    bool judged = false;
    for (const Comparison& c : comparisons) {
      if (c.kind != Comparison::Kind::kCameraPair || c.projector != p || !c.disagreement.enough) {
        continue;
      }
      judged = true;
      note(p, c);
      if (c.disagreement.disagrees) {
        auto& h = out[static_cast<std::size_t>(p)];
        h.verdict = Verdict::kDrifted;
        h.reason = rig.cameras[static_cast<std::size_t>(c.camera)].id + " and " +
                   rig.cameras[static_cast<std::size_t>(c.otherCamera)].id +
                   " disagree on its stripes by " + fixed(c.disagreement.systematicMm) +
                   " mm (threshold " + fixed(c.disagreement.thresholdMm) + " mm)";
      }
    }
    if (judged && out[static_cast<std::size_t>(p)].verdict != Verdict::kDrifted) {
      out[static_cast<std::size_t>(p)].verdict = Verdict::kGood;
      out[static_cast<std::size_t>(p)].reason = "both cameras agree on its stripes";
    }
    return judged;
  }

  // Projector pairs: the one that disagrees with at least two others, and with no one it overlaps.
  [[nodiscard]] bool oddOneOut(int p) const {
    int disagreeing = 0;
    for (const Comparison& c : comparisons) {
      if (c.kind == Comparison::Kind::kProjectorPair && involves(c, p) && c.disagreement.enough) {
        if (!c.disagreement.disagrees) {
          return false;
        }
        ++disagreeing;
      }
    }
    return disagreeing >= 2;
  }

  void byProjectorPairs(int p, const std::vector<bool>& named,
                        const std::vector<bool>& judgedByCameras) {
    auto& h = out[static_cast<std::size_t>(p)];
    if (named[static_cast<std::size_t>(p)]) {
      h.verdict = Verdict::kDrifted;
      h.reason = "disagrees with every other projector it overlaps";
      return;
    }
    bool overlap = false;
    std::vector<std::string> unexplained;
    std::vector<std::string> explained;  // disagreeing partners named (or judged) elsewhere
    for (const Comparison& c : comparisons) {
      if (c.kind != Comparison::Kind::kProjectorPair || !involves(c, p) || !c.disagreement.enough) {
        continue;
      }
      overlap = true;
      note(p, c);
      const int q = partner(c, p);
      if (!c.disagreement.disagrees) {
        continue;
      }
      if (named[static_cast<std::size_t>(q)] || judgedByCameras[static_cast<std::size_t>(q)]) {
        explained.push_back(id(q));
      } else {
        unexplained.push_back(id(q));
      }
    }
    if (!overlap) {
      h.verdict = Verdict::kNoOverlap;
      h.reason = "overlaps no other projector enough to compare";
    } else if (unexplained.empty()) {
      h.verdict = Verdict::kGood;
      h.reason = explained.empty() ? "agrees with every projector it overlaps"
                                   : "disagrees only with " + explained.front() +
                                         ", which the other comparisons blame";
    } else {
      h.verdict = Verdict::kSuspect;
      h.reason = "disagrees with " + unexplained.front() + "; " + id(p) + " or " +
                 unexplained.front() + " moved, the rig cannot tell which";
    }
  }

  // Two projectors that only disagree with each other: the disagreement's shape may decide.
  std::expected<void, std::string> byShape(const std::vector<CameraDepths>& depths,
                                           const CheckOptions& options) {
    for (Comparison& c : comparisons) {
      const int p = c.projector;
      const int q = c.otherProjector;
      if (c.kind != Comparison::Kind::kProjectorPair || !c.disagreement.disagrees ||
          out[static_cast<std::size_t>(p)].verdict != Verdict::kSuspect ||
          out[static_cast<std::size_t>(q)].verdict != Verdict::kSuspect) {
        continue;
      }
      const auto& d = *std::ranges::find(depths, c.camera, &CameraDepths::camera);
      const auto a = attributeByShape(rig, d, p, q, c.disagreement, options.pipeline,
                                      options.thresholds.blockPx);
      if (!a) {
        return std::unexpected(a.error());
      }
      c.shapeFitted = true;
      c.shapeResidualMm = a->residualMm;
      const std::string fits = "pose fits leave " + fixed(a->residualMm[0]) + " mm (" + id(p) +
                               ") and " + fixed(a->residualMm[1]) + " mm (" + id(q) + ")";
      if (a->named < 0) {
        out[static_cast<std::size_t>(p)].reason += "; " + fits;
        out[static_cast<std::size_t>(q)].reason += "; " + fits;
        continue;
      }
      const int moved = a->named == 0 ? p : q;
      const int kept = a->named == 0 ? q : p;
      out[static_cast<std::size_t>(moved)].verdict = Verdict::kDrifted;
      out[static_cast<std::size_t>(moved)].reason =
          "the disagreement with " + id(kept) + " has the shape of its own pose change: " + fits;
      out[static_cast<std::size_t>(kept)].verdict = Verdict::kGood;
      out[static_cast<std::size_t>(kept)].reason = "the disagreement with " + id(moved) +
                                                   " has the shape of " + id(moved) +
                                                   "'s pose change";
    }
    return {};
  }
};

std::string summarise(const algo::Rig& rig, const std::vector<ProjectorHealth>& projectors) {
  std::vector<std::string> drifted;
  std::vector<std::string> suspects;
  std::vector<std::string> unjudged;
  for (const auto& h : projectors) {
    if (h.verdict == Verdict::kDrifted) {
      drifted.push_back(h.id);
    } else if (h.verdict == Verdict::kSuspect) {
      suspects.push_back(h.id);
    } else if (h.verdict == Verdict::kNoOverlap) {
      unjudged.push_back(h.id);
    }
  }
  const auto join = [](const std::vector<std::string>& ids, const char* word) {
    std::string s;
    for (std::size_t i = 0; i < ids.size(); ++i) {
      s += (i == 0 ? "" : (i + 1 == ids.size() ? word : ", ")) + ids[i];
    }
    return s;
  };
  if (!drifted.empty()) {
    return "drifted: " + join(drifted, " and ") + " (recalibrate)";
  }
  if (!suspects.empty()) {
    return "drifted: " + join(suspects, " or ") + " (recalibrate)";
  }
  if (!unjudged.empty()) {
    return "not enough overlap to judge " + join(unjudged, " and ") +
           " (scan a scene that the projectors light together)";
  }
  return "good: all " + std::to_string(rig.projectors.size()) + " projectors agree";
}

}  // namespace

const char* verdictName(Verdict verdict) {
  switch (verdict) {
    case Verdict::kGood:
      return "good";
    case Verdict::kDrifted:
      return "drifted";
    case Verdict::kSuspect:
      return "drifted?";
    case Verdict::kNoOverlap:
      return "not enough overlap";
  }
  return "?";
}

std::expected<CheckReport, std::string> checkRig(const algo::Rig& rig,
                                                 const std::vector<CameraFrame>& frames,
                                                 const CheckOptions& options) {
  std::vector<CameraDepths> depths;
  for (const CameraFrame& f : frames) {
    if (f.camera >= rig.cameras.size()) {
      return std::unexpected("camera " + std::to_string(f.camera) + ": the rig has " +
                             std::to_string(rig.cameras.size()) + " cameras");
    }
    const int cam = static_cast<int>(f.camera);
    if (std::ranges::find(depths, cam, &CameraDepths::camera) != depths.end()) {
      return std::unexpected(rig.cameras[f.camera].id + ": two images of one camera");
    }
    auto d = decodeCameraDepths(rig, cam, f.image, options.pipeline);
    if (!d) {
      return std::unexpected(d.error());
    }
    depths.push_back(std::move(*d));
  }
  CheckReport report;
  const int projectors = static_cast<int>(rig.projectors.size());
  for (const CameraDepths& d : depths) {
    for (int p = 0; p < projectors; ++p) {
      for (int q = p + 1; q < projectors; ++q) {
        report.comparisons.push_back(
            {Comparison::Kind::kProjectorPair,
             d.camera,
             d.camera,
             p,
             q,
             fitDisagreement(projectorPairField(d, p, q), options.thresholds),
             false,
             {}});
      }
    }
  }
  for (std::size_t i = 0; i < depths.size(); ++i) {
    for (std::size_t j = i + 1; j < depths.size(); ++j) {
      for (int p = 0; p < projectors; ++p) {
        report.comparisons.push_back(
            {Comparison::Kind::kCameraPair,
             depths[i].camera,
             depths[j].camera,
             p,
             p,
             fitDisagreement(crossCameraField(rig, depths[i], depths[j], p), options.thresholds),
             false,
             {}});
      }
    }
  }

  Judge judge{rig, report.comparisons, {}};
  for (const auto& p : rig.projectors) {
    judge.out.push_back({p.id, Verdict::kNoOverlap, 0.0, "overlaps nothing enough to compare"});
  }
  std::vector<bool> judgedByCameras(static_cast<std::size_t>(projectors));
  std::vector<bool> named(static_cast<std::size_t>(projectors));
  for (int p = 0; p < projectors; ++p) {
    judgedByCameras[static_cast<std::size_t>(p)] = judge.byCameras(p);
    named[static_cast<std::size_t>(p)] = judge.oddOneOut(p);
  }
  for (int p = 0; p < projectors; ++p) {
    if (!judgedByCameras[static_cast<std::size_t>(p)]) {
      judge.byProjectorPairs(p, named, judgedByCameras);
    }
  }
  if (auto ok = judge.byShape(depths, options); !ok) {
    return std::unexpected(ok.error());
  }
  report.projectors = std::move(judge.out);
  report.healthy = std::ranges::all_of(
      report.projectors, [](const ProjectorHealth& h) { return h.verdict == Verdict::kGood; });
  report.summary = summarise(rig, report.projectors);
  return report;
}

}  // namespace smx::health
