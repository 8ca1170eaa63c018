#include "smx/eval/frame_eval.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <stdexcept>
#include <string>

#include "smx/algo/lens.hpp"
#include "smx/algo/triangulation.hpp"

namespace smx::eval {

algo::PipelineOptions evalPipelineOptions() {
  algo::PipelineOptions options;
  options.nominalDepthM = kEvalNominalDepthM;
  return options;
}

std::unique_ptr<PipelineRun> makePipeline(const algo::Rig& rig, int camera,
                                          const algo::PipelineOptions& options) {
  const auto setup = algo::prepareCameraPipeline(rig, camera, options);
  if (!setup) {
    throw std::runtime_error("pipeline setup: " + setup.error());
  }
  const auto bytes = algo::CameraPipeline::workspaceBytes(*setup);
  if (!bytes) {
    throw std::runtime_error(std::string("pipeline layout: ") + bytes.error().message);
  }
  auto run = std::make_unique<PipelineRun>();
  run->memory.resize(*bytes);
  run->arena = std::make_unique<algo::Arena>(run->memory);
  auto pipeline = algo::CameraPipeline::create(*setup, *run->arena);
  if (!pipeline) {
    throw std::runtime_error(std::string("pipeline create: ") + pipeline.error().message);
  }
  run->pipeline = std::make_unique<algo::CameraPipeline>(*pipeline);
  return run;
}

std::unique_ptr<PipelineRun> runPipeline(const SimFrame& frame, int camera,
                                         const algo::PipelineOptions& options) {
  auto run = makePipeline(frame.rig, camera, options);
  if (auto ok = run->pipeline->run(frame.image.view()); !ok) {
    throw std::runtime_error(std::string("pipeline run: ") + ok.error().message);
  }
  return run;
}

Mask litRegion(const SimFrame& frame, const RegionSpec& spec) {
  std::vector<algo::ImageView<const std::uint8_t>> lits;
  lits.reserve(frame.lit.size());
  for (const auto& lit : frame.lit) {
    lits.push_back(lit.view());
  }
  Mask m = spec.exactly ? litByExactly(lits, spec.patterns) : litByAtLeast(lits, spec.patterns);
  if (spec.smooth) {
    m = smoothOnly(erode(m, 3), frame.depth.view(), 0.02);
  }
  if (spec.projector >= 0) {
    const auto& mine = frame.lit.at(static_cast<std::size_t>(spec.projector));
    for (int y = 0; y < m.height; ++y) {
      for (int x = 0; x < m.width; ++x) {
        m.at(x, y) = (m.at(x, y) != 0 && mine.at(x, y) != 0) ? 255 : 0;
      }
    }
  }
  return m;
}

namespace {
DepthScoreOptions scoreOptions(const SimFrame& frame, int camera, double baselineM) {
  DepthScoreOptions o;
  o.fxPx = frame.rig.cameras.at(static_cast<std::size_t>(camera)).fx();
  o.baselineM = baselineM;
  return o;
}
}  // namespace

DepthScore scoreMerged(const SimFrame& frame, int camera, const algo::CameraPipeline& pipeline,
                       const Mask& region) {
  double baseline = 0;
  for (int p = 0; p < pipeline.projectors(); ++p) {
    baseline += algo::baselineM(frame.rig, camera, p) / pipeline.projectors();
  }
  return scoreDepth(pipeline.merged(), frame.depth.view(), region.view(),
                    scoreOptions(frame, camera, baseline));
}

DepthScore scorePair(const SimFrame& frame, int camera, const algo::CameraPipeline& pipeline,
                     int projector, const Mask& region) {
  return scoreDepth(pipeline.depth(projector), frame.depth.view(), region.view(),
                    scoreOptions(frame, camera, algo::baselineM(frame.rig, camera, projector)));
}

FrameFigures measureFrame(const SimFrame& frame, int camera, const algo::CameraPipeline& pipeline) {
  FrameFigures fig;
  fig.mergedAll = scoreMerged(frame, camera, pipeline, litRegion(frame, {}));
  fig.mergedSmooth = scoreMerged(frame, camera, pipeline, litRegion(frame, {.smooth = true}));
  fig.merged2 = scoreMerged(frame, camera, pipeline,
                            litRegion(frame, {.patterns = 2, .exactly = true, .smooth = true}));
  fig.merged3 = scoreMerged(frame, camera, pipeline,
                            litRegion(frame, {.patterns = 3, .exactly = true, .smooth = true}));
  for (int p = 0; p < pipeline.projectors(); ++p) {
    fig.pairs.push_back(
        scorePair(frame, camera, pipeline, p, litRegion(frame, {.smooth = true, .projector = p})));
    fig.pairs2.push_back(scorePair(
        frame, camera, pipeline, p,
        litRegion(frame, {.patterns = 2, .exactly = true, .smooth = true, .projector = p})));
    fig.pairs3.push_back(scorePair(
        frame, camera, pipeline, p,
        litRegion(frame, {.patterns = 3, .exactly = true, .smooth = true, .projector = p})));
  }
  return fig;
}

PlaneFit fitPlane(const algo::Camera& camera, algo::ConstDepthPlane depth,
                  algo::ImageView<const std::uint8_t> region, double depthUnitM) {
  if (depth.width() != region.width() || depth.height() != region.height()) {
    throw std::invalid_argument("fitPlane: depth and region differ in size");
  }
  PlaneFit fit;
  std::vector<Eigen::Vector3d> points;
  for (int y = 0; y < depth.height(); ++y) {
    for (int x = 0; x < depth.width(); ++x) {
      if (region(x, y) == 0) {
        continue;
      }
      ++fit.regionPixels;
      if (depth(x, y) == algo::kNoDepth) {
        continue;
      }
      if (const auto p = algo::lens::devicePoint(
              camera, {static_cast<double>(x), static_cast<double>(y)}, depth(x, y) * depthUnitM)) {
        points.emplace_back((*p)[0], (*p)[1], (*p)[2]);
      }
    }
  }
  fit.points = static_cast<int>(points.size());
  fit.fillRate = fit.regionPixels > 0 ? static_cast<double>(fit.points) / fit.regionPixels : 0;
  if (points.size() < 3) {
    return fit;
  }
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : points) {
    mean += p;
  }
  mean /= static_cast<double>(points.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& p : points) {
    scatter += (p - mean) * (p - mean).transpose();
  }
  // The normal is the direction of least spread; its eigenvalue is the sum of squared distances.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
  const double sumSquares = std::max(solver.eigenvalues()(0), 0.0);
  fit.rmsMm = 1000.0 * std::sqrt(sumSquares / static_cast<double>(points.size()));
  return fit;
}

}  // namespace smx::eval
