#pragma once

#include <cstddef>
#include <expected>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

// The one way a command writes files (docs/cli.md, "Output files"). Names are plain file names
// checked here, so a path built from an id, a device's answer or a typo cannot leave the folder.
// Each file is written under a temporary name in the folder and renamed onto its name by
// commit(), so a file is complete or absent, never half-written (a full disk, a crash). Dropped
// without commit(), an OutputFolder removes its temporary files and the folders it created when
// they are empty: a failed command leaves what existed as it was.
namespace smx::host {

class OutputFolder {
 public:
  // Writes the file at the path given; its errors become the command's.
  using Writer = std::function<std::expected<void, std::string>(const std::filesystem::path&)>;

  // Creates `dir` and its missing parents.
  [[nodiscard]] static std::expected<OutputFolder, std::string> create(std::filesystem::path dir);

  OutputFolder(OutputFolder&& other) noexcept;
  OutputFolder& operator=(OutputFolder&&) = delete;
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;
  ~OutputFolder();

  // Writes `name` (a plain file name, see fileNameProblem) through `write`. The file takes its
  // name at commit(); until then an older file of that name is untouched.
  [[nodiscard]] std::expected<void, std::string> write(std::string_view name, const Writer& write);
  // `text` as the file `name`.
  [[nodiscard]] std::expected<void, std::string> writeText(std::string_view name,
                                                           std::string_view text);
  // Renames every file written since the last commit onto its name.
  [[nodiscard]] std::expected<void, std::string> commit();

  [[nodiscard]] const std::filesystem::path& path() const { return dir_; }
  // Where `name` is once committed (for messages).
  [[nodiscard]] std::filesystem::path pathOf(std::string_view name) const { return dir_ / name; }

 private:
  struct Staged {
    std::filesystem::path temporary;
    std::filesystem::path final;
  };
  OutputFolder(std::filesystem::path dir, std::vector<std::filesystem::path> created);

  std::filesystem::path dir_;
  std::vector<std::filesystem::path> created_;  // folders this made, deepest last
  std::vector<Staged> staged_;
  bool moved_ = false;
};

// Why `name` is not a plain file name an output may have (1 to 128 characters of A-Z a-z 0-9
// _ - ., starting with a letter or digit: no separator, no "..", no control character), or
// nothing when it is one.
[[nodiscard]] std::optional<std::string> fileNameProblem(std::string_view name);

}  // namespace smx::host
