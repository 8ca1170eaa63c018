#pragma once

#include <nlohmann/json.hpp>
#include <optional>

#include "smx/config/field_reader.hpp"
#include "smx/sim/handheld.hpp"

// scene.json's "handheld" block (docs/scene-format.md): the rig's hand-held trajectory.
namespace smx::config::detail {

// The keys and types of `doc["handheld"]`, then its values (checkHandheld); the axis is
// normalised. Absent: `out` stays empty.
void readHandheld(FieldReader& r, const nlohmann::json& doc, std::optional<sim::Handheld>& out);

// The value rules, with the JSON paths of the fields: for scenes read and built in memory.
void checkHandheld(FieldReader& r, const sim::Handheld& h);

}  // namespace smx::config::detail
