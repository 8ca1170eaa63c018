#pragma once

#include <expected>
#include <filesystem>
#include <string>
#include <string_view>

#include "smx/algo/rig.hpp"
#include "smx/hal/board_config.hpp"

// board.json, format `stripemux-board/1` (docs/boards.md): a board as data. Read at start-up,
// validated completely, every failure naming the file and the field.
namespace smx::config {

inline constexpr std::string_view kBoardFormat = "stripemux-board/1";

struct BoardError {
  std::string file;
  std::string field;
  std::string problem;
  [[nodiscard]] std::string message() const;
};

struct Board {
  hal::BoardConfig config;
  algo::Rig rig;
};

// `text` is a board.json; relative paths in it (the rig, a replay folder) are relative to `dir`.
[[nodiscard]] std::expected<Board, BoardError> parseBoard(std::string_view text,
                                                          const std::filesystem::path& dir);
// `path` is a board folder (its board.json is read) or a board.json file.
[[nodiscard]] std::expected<Board, BoardError> loadBoard(const std::filesystem::path& path);

}  // namespace smx::config
