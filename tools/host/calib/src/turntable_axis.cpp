#include "smx/calib/turntable_axis.hpp"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "smx/text/printf_text.hpp"

namespace smx::calib {

namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;
// Relative rotations that miss the fitted axis by more than this are a target that moved on the
// table, not corner noise (a few hundredths of a degree on a sharp target).
constexpr double kSlipDeg = 1.0;

Eigen::Vector3d rotationVector(const Eigen::Matrix3d& r) {
  const Eigen::AngleAxisd aa(r);
  return aa.axis() * aa.angle();
}

std::vector<Eigen::Vector3d> worldCorners(const TableView& view,
                                          const std::vector<TargetPoint>& corners) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(corners.size());
  for (const auto& c : corners) {
    out.emplace_back(view.R * Eigen::Vector3d(c.x, c.y, 0.0) + view.t);
  }
  return out;
}

}  // namespace

std::expected<AxisFit, std::string> fitTurntableAxis(std::span<const TableView> views,
                                                     const Target& target) {
  if (std::ssize(views) < kMinTableViews) {
    return std::unexpected(text::printfText(
        "the target was found at %zu table angles, at least %d are needed: capture more angles",
        views.size(), kMinTableViews));
  }
  const auto [lo, hi] = std::ranges::minmax(views, {}, &TableView::angleDeg);
  if (hi.angleDeg - lo.angleDeg < kMinTableSpanDeg) {
    return std::unexpected(
        text::printfText("the table angles span %.1f°, at least %.0f° are needed: turn the table "
                         "further between the first and the last view",
                         hi.angleDeg - lo.angleDeg, kMinTableSpanDeg));
  }

  // Direction: every pair's relative rotation R_j·R_iᵀ is a turn by (θ_j − θ_i) about the axis,
  // so its rotation vector is (θ_j − θ_i)·a; least squares over the pairs.
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double weight = 0.0;
  for (std::size_t i = 0; i < views.size(); ++i) {
    for (std::size_t j = i + 1; j < views.size(); ++j) {
      const double turn = (views[j].angleDeg - views[i].angleDeg) / kDegPerRad;
      sum += turn * rotationVector(views[j].R * views[i].R.transpose());
      weight += turn * turn;
    }
  }
  if (weight <= 0.0 || sum.norm() <= 0.0) {
    return std::unexpected(std::string("the target did not turn between the views"));
  }
  AxisFit fit;
  fit.angleScale = sum.norm() / weight;
  fit.direction = sum.normalized();

  // Misses of every pair's rotation against the model; a view whose pairs miss by more than
  // noise is named (the median of its pairs, so that one bad view does not blame the others).
  const std::size_t n = views.size();
  std::vector<std::vector<double>> missesOf(n);
  double rotationSq = 0.0;
  int pairs = 0;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      const double turn = (views[j].angleDeg - views[i].angleDeg) / kDegPerRad * fit.angleScale;
      const Eigen::Matrix3d model(Eigen::AngleAxisd(turn, fit.direction));
      const double miss =
          Eigen::AngleAxisd(model.transpose() * views[j].R * views[i].R.transpose()).angle() *
          kDegPerRad;
      missesOf[i].push_back(miss);
      missesOf[j].push_back(miss);
      rotationSq += miss * miss;
      ++pairs;
    }
  }
  std::size_t worst = 0;
  double worstMedian = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    auto& m = missesOf[k];
    std::ranges::nth_element(m, m.begin() + static_cast<std::ptrdiff_t>(m.size() / 2));
    if (const double median = m[m.size() / 2]; median > worstMedian) {
      worstMedian = median;
      worst = k;
    }
  }
  if (worstMedian > kSlipDeg) {
    return std::unexpected(text::printfText(
        "%s: the target is turned %.2f° off the table's axis against the other views (it slid "
        "or was moved, or the table's angle for it is wrong): keep it still on the table and "
        "capture again",
        views[worst].name.c_str(), worstMedian));
  }
  fit.rotationRmsDeg = std::sqrt(rotationSq / pairs);

  // Point: a corner X_i of view i is at X_j = Q·(X_i − p) + p in view j, Q the model turn, so
  // (I − Q)·p = X_j − Q·X_i. Along the axis p is free: solve in the plane across it.
  const auto corners = innerCorners(target);
  std::vector<std::vector<Eigen::Vector3d>> world;
  world.reserve(views.size());
  for (const auto& view : views) {
    world.push_back(worldCorners(view, corners));
  }
  const Eigen::Vector3d u = fit.direction.unitOrthogonal();
  const Eigen::Vector3d w = fit.direction.cross(u);
  Eigen::Matrix2d normal = Eigen::Matrix2d::Zero();
  Eigen::Vector2d rhs = Eigen::Vector2d::Zero();
  for (std::size_t i = 0; i < views.size(); ++i) {
    for (std::size_t j = i + 1; j < views.size(); ++j) {
      const double turn = (views[j].angleDeg - views[i].angleDeg) / kDegPerRad * fit.angleScale;
      const Eigen::Matrix3d q(Eigen::AngleAxisd(turn, fit.direction));
      Eigen::Matrix<double, 3, 2> a;
      a.col(0) = (Eigen::Matrix3d::Identity() - q) * u;
      a.col(1) = (Eigen::Matrix3d::Identity() - q) * w;
      const Eigen::Matrix2d ata = a.transpose() * a;
      for (std::size_t k = 0; k < corners.size(); ++k) {
        normal += ata;
        rhs += a.transpose() * (world[j][k] - q * world[i][k]);
      }
    }
  }
  const Eigen::Vector2d across = normal.ldlt().solve(rhs);
  fit.point = across[0] * u + across[1] * w;

  // Residuals: every view against the first turned about the fitted line.
  double allSq = 0.0;
  std::size_t count = 0;
  for (std::size_t j = 0; j < views.size(); ++j) {
    const double turn = (views[j].angleDeg - views[0].angleDeg) / kDegPerRad * fit.angleScale;
    const Eigen::Matrix3d q(Eigen::AngleAxisd(turn, fit.direction));
    double viewSq = 0.0;
    for (std::size_t k = 0; k < corners.size(); ++k) {
      const Eigen::Vector3d predicted = q * (world[0][k] - fit.point) + fit.point;
      viewSq += (predicted - world[j][k]).squaredNorm();
    }
    fit.viewRmsM.push_back(std::sqrt(viewSq / static_cast<double>(corners.size())));
    allSq += viewSq;
    count += corners.size();
  }
  fit.cornerRmsM = std::sqrt(allSq / static_cast<double>(count));
  return fit;
}

}  // namespace smx::calib
