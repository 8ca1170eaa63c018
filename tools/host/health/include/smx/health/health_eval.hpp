#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "smx/health/check.hpp"

// The health check's figures (`stripemux eval --only health`, docs/health.md): every named scene
// on every example rig (boards/sim), rendered once per camera with the correct rig, then checked
// with the correct rig (false alarms) and with each projector moved by each specified drift
// (drift.hpp; detections and whether the right projector is named). Host code; throws
// std::runtime_error naming the scene or rig that failed.
namespace smx::health {

struct HealthCase {
  std::string rigFile;
  std::string scene;
  int projector = -1;  // the moved projector; −1: the correct rig
  std::string drift;   // what moved it
  CheckReport report;
  bool flagged = false;  // not healthy
  bool named = false;    // the moved projector drifted, every other good
  bool wrong = false;    // another projector named drifted
};

struct HealthEvalOptions {
  std::vector<std::string> scenes;  // empty: every named scene
  std::vector<std::string> rigFiles = {"rig_2proj_1cam.json", "rig_2proj_2cam.json",
                                       "rig_3proj_1cam.json", "rig_3proj_2cam.json"};
  std::uint64_t seed = 1;
  int supersampling = 0;
  std::function<void(const std::string&)> progress;
};

[[nodiscard]] std::vector<HealthCase> runHealthEval(const HealthEvalOptions& options);

// docs/health.md: detection and naming rates per rig and drift, false alarms per rig and scene.
[[nodiscard]] std::string healthMarkdown(const std::vector<HealthCase>& cases,
                                         const std::string& commandLine);

}  // namespace smx::health
