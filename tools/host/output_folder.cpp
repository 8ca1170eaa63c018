#include "output_folder.hpp"

#include <unistd.h>

#include <atomic>
#include <fstream>
#include <ranges>
#include <system_error>
#include <utility>

#include "smx/config/identifier.hpp"

namespace smx::host {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kMaxFileName = 128;

// The folders create_directories(dir) would make, outermost first.
std::vector<fs::path> missingFolders(const fs::path& dir) {
  std::vector<fs::path> missing;
  std::error_code ec;
  for (fs::path p = dir; !p.empty() && !fs::exists(fs::symlink_status(p, ec));
       p = p.parent_path()) {
    missing.insert(missing.begin(), p);
    if (p == p.parent_path()) {
      break;
    }
  }
  return missing;
}

// A temporary name unique to this process and call, hidden, next to the final file so that the
// rename stays on one file system.
fs::path temporaryFor(const fs::path& final) {
  static std::atomic<unsigned> counter{0};
  return final.parent_path() / ("." + final.filename().string() + ".part" +
                                std::to_string(::getpid()) + "-" + std::to_string(counter++));
}

// Writers name the file they were given; the user knows it by its final name.
std::string renamed(std::string message, const fs::path& temporary, const fs::path& final) {
  const std::string from = temporary.string();
  for (auto at = message.find(from); at != std::string::npos; at = message.find(from, at)) {
    message.replace(at, from.size(), final.string());
    at += final.string().size();
  }
  return message;
}

}  // namespace

std::optional<std::string> fileNameProblem(std::string_view name) {
  if (name.empty() || name.size() > kMaxFileName) {
    return "an output file name must be 1 to " + std::to_string(kMaxFileName) +
           " characters long, got " + std::to_string(name.size());
  }
  if (!config::isIdentifierStart(name.front())) {
    return "an output file name must start with a letter or digit";
  }
  for (const char c : name) {
    if (!config::isIdentifierChar(c)) {
      return "an output file name may hold only A-Z a-z 0-9 _ - . (no folder, no control "
             "character)";
    }
  }
  if (name.find("..") != std::string_view::npos) {
    return "an output file name must not contain \"..\"";
  }
  return std::nullopt;
}

std::expected<OutputFolder, std::string> OutputFolder::create(fs::path dir) {
  if (dir.empty()) {
    dir = ".";
  }
  auto missing = missingFolders(dir);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) {
    return std::unexpected("cannot create the folder " + dir.string() + ": " + ec.message());
  }
  if (!fs::is_directory(dir, ec)) {
    return std::unexpected(dir.string() + " is not a folder");
  }
  return OutputFolder(std::move(dir), std::move(missing));
}

OutputFolder::OutputFolder(fs::path dir, std::vector<fs::path> created)
    : dir_(std::move(dir)), created_(std::move(created)) {}

OutputFolder::OutputFolder(OutputFolder&& other) noexcept
    : dir_(std::move(other.dir_)),
      created_(std::move(other.created_)),
      staged_(std::move(other.staged_)) {
  other.moved_ = true;
}

OutputFolder::~OutputFolder() {
  if (moved_) {
    return;
  }
  std::error_code ec;
  for (const auto& file : staged_) {
    fs::remove(file.temporary, ec);
  }
  // Only empty folders go: remove() refuses the others, and whatever is in them stays.
  for (const auto& folder : std::ranges::reverse_view(created_)) {
    if (!fs::is_empty(folder, ec) || !fs::remove(folder, ec)) {
      break;
    }
  }
}

std::expected<void, std::string> OutputFolder::write(std::string_view name, const Writer& write) {
  if (auto problem = fileNameProblem(name)) {
    return std::unexpected(*problem + ": " + std::string(name.substr(0, 64)));
  }
  const fs::path final = dir_ / name;
  const fs::path temporary = temporaryFor(final);
  std::error_code ec;
  fs::remove(temporary, ec);  // a leftover of a crashed run with this pid: never write through it
  staged_.push_back({temporary, final});
  if (auto ok = write(temporary); !ok) {
    return std::unexpected(renamed(ok.error(), temporary, final));
  }
  return {};
}

std::expected<void, std::string> OutputFolder::writeText(std::string_view name,
                                                         std::string_view text) {
  return write(name, [&](const fs::path& file) -> std::expected<void, std::string> {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    out.close();
    if (!out) {
      return std::unexpected("cannot write " + file.string());
    }
    return {};
  });
}

std::expected<void, std::string> OutputFolder::commit() {
  for (std::size_t i = 0; i < staged_.size(); ++i) {
    std::error_code ec;
    fs::rename(staged_[i].temporary, staged_[i].final, ec);
    if (ec) {
      staged_.erase(staged_.begin(), staged_.begin() + static_cast<std::ptrdiff_t>(i));
      return std::unexpected("cannot write " + staged_.front().final.string() + ": " +
                             ec.message());
    }
  }
  staged_.clear();
  return {};
}

}  // namespace smx::host
