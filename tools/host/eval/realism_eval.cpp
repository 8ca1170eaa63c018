#include "smx/eval/realism_eval.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <utility>

#include "smx/algo/camera_pipeline.hpp"
#include "smx/algo/triangulation.hpp"
#include "smx/eval/frame_eval.hpp"

namespace smx::eval {

namespace {

Mask without(Mask a, const Mask& b) {
  for (std::size_t i = 0; i < a.pixels.size(); ++i) {
    a.pixels[i] = (a.pixels[i] != 0 && b.pixels[i] == 0) ? 255 : 0;
  }
  return a;
}

bool jump(float a, float b) {
  const bool fa = std::isfinite(a);
  const bool fb = std::isfinite(b);
  if (fa != fb) {
    return true;
  }
  return fa && std::abs(a - b) > 0.02F * std::min(a, b);
}

std::string rigText(const RealismCase& c, int camera) {
  std::string s;
  for (std::size_t p = 0; p < c.rig.projectors.size(); ++p) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "%sp%zu %.0f cm %.0f° %.1f px", p == 0 ? "" : "; ", p,
                  100.0 * algo::baselineM(c.rig, camera, static_cast<int>(p)), c.axisDeg[p],
                  c.stripeWidthPx[p]);
    s += buf;
  }
  return s;
}

}  // namespace

Mask discontinuityBand(algo::ImageView<const float> depth, int radiusPx) {
  const int w = depth.width();
  const int h = depth.height();
  Mask edge = Mask::filled(w, h, 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const bool right = x + 1 < w && jump(depth(x, y), depth(x + 1, y));
      const bool down = y + 1 < h && jump(depth(x, y), depth(x, y + 1));
      if (right) {
        edge.at(x, y) = 255;
        edge.at(x + 1, y) = 255;
      }
      if (down) {
        edge.at(x, y) = 255;
        edge.at(x, y + 1) = 255;
      }
    }
  }
  Mask band = Mask::filled(w, h, 0);
  const int r2 = radiusPx * radiusPx;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (edge.at(x, y) == 0) {
        continue;
      }
      for (int dy = -radiusPx; dy <= radiusPx; ++dy) {
        for (int dx = -radiusPx; dx <= radiusPx; ++dx) {
          const int xx = x + dx;
          const int yy = y + dy;
          if (dx * dx + dy * dy <= r2 && xx >= 0 && yy >= 0 && xx < w && yy < h) {
            band.at(xx, yy) = 255;
          }
        }
      }
    }
  }
  return band;
}

Mask resolvableRegion(const SimFrame& frame) {
  Mask m = litRegion(frame, {.smooth = true});
  for (int y = 0; y < m.height; ++y) {
    for (int x = 0; x < m.width; ++x) {
      if (m.at(x, y) == 0) {
        continue;
      }
      for (std::size_t p = 0; p < frame.lit.size(); ++p) {
        if (frame.lit[p].at(x, y) == 0) {
          continue;
        }
        const auto g = stripeGradient(frame.stripe[p].view(), x, y);
        if (!g || 1.0 / g->magnitude < kResolvableStripePx) {
          m.at(x, y) = 0;
          break;
        }
      }
    }
  }
  return m;
}

double medianStripeWidthPx(const SimFrame& frame, int projector) {
  return medianStripeWidthPx(frame.stripe.at(static_cast<std::size_t>(projector)).view());
}

std::vector<RealismRun> runRealismCase(const RealismCase& c, std::uint64_t seed,
                                       int supersampling) {
  algo::PipelineOptions options = evalPipelineOptions();
  // A user sets the depth the directions are predicted at to the rig's working distance.
  options.nominalDepthM = c.workingDistanceM;
  std::vector<RealismRun> runs;
  for (int cam = 0; cam < static_cast<int>(c.rig.cameras.size()); ++cam) {
    RealismRun r;
    r.caseIndex = c.index;
    r.camera = cam;
    r.summary = c.summary;
    r.rig = rigText(c, cam);
    r.projectors = static_cast<int>(c.rig.projectors.size());
    r.workingDistanceM = c.workingDistanceM;
    if (auto setup = algo::prepareCameraPipeline(c.rig, cam, options); !setup) {
      r.refused = true;
      r.reason = setup.error();
      runs.push_back(std::move(r));
      continue;
    }
    const SimFrame f = renderSimFrame(
        c.rig, c.scene, {.camera = cam, .seed = seed, .supersampling = supersampling});
    auto run = makePipeline(f.rig, cam, options);
    if (auto ok = run->pipeline->run(f.image.view()); !ok) {
      throw std::runtime_error("realism case " + std::to_string(c.index) +
                               ": pipeline run: " + ok.error().message);
    }
    const auto& pipe = *run->pipeline;
    const Mask lit = litRegion(f, {});
    r.lit = scoreMerged(f, cam, pipe, lit);
    r.smooth = scoreMerged(f, cam, pipe, litRegion(f, {.smooth = true}));
    r.lit2 =
        scoreMerged(f, cam, pipe, litRegion(f, {.patterns = 2, .exactly = true, .smooth = true}));
    r.lit3 =
        scoreMerged(f, cam, pipe, litRegion(f, {.patterns = 3, .exactly = true, .smooth = true}));
    const Mask resolvable = resolvableRegion(f);
    const Mask outsideBand = without(lit, discontinuityBand(f.depth.view(), kDiscontinuityBandPx));
    r.resolvable = scoreMerged(f, cam, pipe, resolvable);
    r.outsideBand = scoreMerged(f, cam, pipe, outsideBand);
    r.attribution = attributeRun(f, cam, pipe.merged(), outsideBand, resolvable);
    std::vector<algo::ConstStripePlane> stripes;
    std::vector<algo::ConstDepthPlane> depths;
    for (int p = 0; p < pipe.projectors(); ++p) {
      stripes.push_back(pipe.stripe(p));
      depths.push_back(pipe.depth(p));
    }
    r.wrongDepth = classifyWrongDepth(stripes, depths, f.stripe, pipe.merged(), f.depth.view(),
                                      outsideBand, options.depthUnitM);
    for (int p = 0; p < r.projectors; ++p) {
      r.medianStripePx.push_back(medianStripeWidthPx(f, p));
    }
    r.image = f.image;
    r.errorMm = depthErrorMapMm(pipe.merged(), f.depth.view());
    runs.push_back(std::move(r));
  }
  return runs;
}

DepthScore sumScores(std::span<const DepthScore> scores) {
  DepthScore t;
  double squares = 0;
  double disparitySquares = 0;
  double sum = 0;
  for (const auto& s : scores) {
    t.regionPixels += s.regionPixels;
    t.valid += s.valid;
    t.gross += s.gross;
    t.inliers += s.inliers;
    t.phantom += s.phantom;
    t.validOutside += s.validOutside;
    t.grossOutside += s.grossOutside;
    t.validTotal += s.validTotal;
    squares += s.inliers * s.rmseMm * s.rmseMm;
    disparitySquares += s.inliers * s.rmsDisparityPx * s.rmsDisparityPx;
    sum += s.inliers * s.meanErrorMm;
    t.maxAbsErrorMm = std::max(t.maxAbsErrorMm, s.maxAbsErrorMm);
  }
  if (t.regionPixels > 0) {
    t.completeness = static_cast<double>(t.valid) / t.regionPixels;
  }
  if (t.valid > 0) {
    t.grossRate = static_cast<double>(t.gross) / t.valid;
  }
  if (t.inliers > 0) {
    t.rmseMm = std::sqrt(squares / t.inliers);
    t.rmsDisparityPx = std::sqrt(disparitySquares / t.inliers);
    t.meanErrorMm = sum / t.inliers;
  }
  return t;
}

std::vector<const RealismRun*> worstRuns(const std::vector<RealismRun>& runs, int count) {
  std::vector<const RealismRun*> order;
  for (const auto& r : runs) {
    if (!r.refused) {
      order.push_back(&r);
    }
  }
  std::ranges::stable_sort(order, [](const RealismRun* a, const RealismRun* b) {
    return a->outsideBand.grossRate > b->outsideBand.grossRate;
  });
  if (order.size() > static_cast<std::size_t>(count)) {
    order.resize(static_cast<std::size_t>(count));
  }
  return order;
}

void keepWorstImages(std::vector<RealismRun>& runs, int keep) {
  const auto worst = worstRuns(runs, keep);
  for (auto& r : runs) {
    if (std::ranges::find(worst, &r) == worst.end()) {
      r.image = {};
      r.errorMm.clear();
      r.errorMm.shrink_to_fit();
    }
  }
}

}  // namespace smx::eval
