#pragma once

#include <optional>
#include <span>
#include <string>

// The rule for a rotation matrix given in a configuration file (rig.json's R, scene.json's pose
// R): orthonormal and right-handed within a tolerance that accepts R printed with 7 digits.
namespace smx::config {

inline constexpr double kRotationTolerance = 1e-6;

// What keeps the row-major 3x3 `r` from being a rotation, e.g. "not a rotation: max |R*R^T - I|
// is 0.0201 (must be at most 1e-06)" or "not a rotation: det R is -1 (must be 1 within 1e-06;
// det -1 is a reflection)"; nullopt for a rotation. Non-finite entries are not a rotation.
[[nodiscard]] std::optional<std::string> rotationProblem(std::span<const double, 9> r);

}  // namespace smx::config
