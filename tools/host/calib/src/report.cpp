#include "smx/calib/report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace smx::calib {
namespace {

using Json = nlohmann::ordered_json;

double rounded(double v, double unit) {
  return std::round(v / unit) * unit;
}

std::string fixed(double v, int decimals) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

}  // namespace

Json reportJson(const Calibration& c) {
  Json out;
  out["format"] = kReportFormat;
  out["verdict"] = c.verdict;
  Json cameras = Json::array();
  for (const CameraFit& fit : c.cameras) {
    Json poses = Json::array();
    for (const PoseUse& use : fit.poses) {
      Json p{{"pose", use.pose}, {"used", use.used}};
      if (use.used) {
        p["rms_px"] = rounded(use.rmsPx, 1e-4);
      } else {
        p["note"] = use.note;
      }
      poses.push_back(std::move(p));
    }
    Json sd;
    const char* names[] = {"fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3"};
    for (std::size_t i = 0; i < fit.sd.size(); ++i) {
      sd[names[i]] = rounded(fit.sd[i], i < 4 ? 1e-3 : 1e-6);
    }
    cameras.push_back({{"id", fit.camera.id},
                       {"rms_px", rounded(fit.rmsPx, 1e-4)},
                       {"standard_deviation", std::move(sd)},
                       {"depth_scale_sd_mm_at_1m", rounded(fit.depthScaleSdMm, 1e-3)},
                       {"fixed_at_nominal", fit.fixedAtNominal},
                       {"poses", std::move(poses)}});
  }
  out["cameras"] = std::move(cameras);
  Json projectors = Json::array();
  for (const ProjectorFit& fit : c.projectors) {
    Json poses = Json::array();
    for (const PoseResidual& r : fit.poses) {
      poses.push_back({{"pose", r.pose},
                       {"samples", r.samples},
                       {"outliers", r.outliers},
                       {"rms_px", rounded(r.rmsPx, 1e-4)},
                       {"rms_mm", rounded(r.rmsMm, 1e-4)}});
    }
    projectors.push_back({{"id", fit.projector.id},
                          {"rms_px", rounded(fit.rmsPx, 1e-4)},
                          {"rms_mm", rounded(fit.rmsMm, 1e-4)},
                          {"samples", fit.samples},
                          {"outliers", fit.outliers},
                          {"fixed_at_nominal", fit.fixedAtNominal},
                          {"poses", std::move(poses)}});
  }
  out["projectors"] = std::move(projectors);
  out["notes"] = c.notes;
  return out;
}

std::string reportText(const Calibration& c) {
  std::ostringstream s;
  s << "verdict: " << c.verdict << "\n";
  for (const CameraFit& fit : c.cameras) {
    int used = 0;
    for (const PoseUse& use : fit.poses) {
      used += use.used ? 1 : 0;
    }
    s << fit.camera.id << ": reprojection RMS " << fixed(fit.rmsPx, 3) << " px over " << used
      << " of " << fit.poses.size() << " poses; focal length ±" << fixed(fit.sd[0], 2)
      << " px, principal point ±" << fixed(std::max(fit.sd[2], fit.sd[3]), 2)
      << " px; depth scale ±" << fixed(fit.depthScaleSdMm, 2) << " mm at 1 m";
    for (const PoseUse& use : fit.poses) {
      if (!use.used) {
        s << "\n  " << use.pose << ": " << use.note;
      }
    }
    s << "\n";
  }
  for (const ProjectorFit& fit : c.projectors) {
    s << fit.projector.id << ": stripe residual RMS " << fixed(fit.rmsPx, 3) << " projector px ("
      << fixed(fit.rmsMm, 3) << " mm) over " << fit.samples << " samples, " << fit.outliers
      << " outliers removed\n";
  }
  for (const std::string& note : c.notes) {
    s << "note: " << note << "\n";
  }
  return s.str();
}

}  // namespace smx::calib
