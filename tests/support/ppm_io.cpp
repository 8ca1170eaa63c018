#include "ppm_io.hpp"

#include <cctype>
#include <fstream>
#include <istream>

namespace smx::test {

namespace {

// Reads the header token by token as netpbm does: whitespace and # comments between tokens.
bool readPpmToken(std::istream& in, std::string& token) {
  token.clear();
  int c = in.get();
  while (c != EOF && (std::isspace(c) != 0 || c == '#')) {
    if (c == '#') {
      while (c != EOF && c != '\n') {
        c = in.get();
      }
    }
    c = in.get();
  }
  while (c != EOF && std::isspace(c) == 0 && c != '#') {
    token.push_back(static_cast<char>(c));
    c = in.get();
  }
  if (c == '#') {
    in.unget();  // a comment right after a token belongs to the next gap
  }
  // The single whitespace after the last header token is consumed with it, as P6 requires.
  return !token.empty();
}

bool parsePositive(const std::string& token, int limit, int& value) {
  if (token.empty() || token.size() > 6 ||
      token.find_first_not_of("0123456789") != std::string::npos) {
    return false;
  }
  value = std::stoi(token);
  return value > 0 && value <= limit;
}

}  // namespace

std::expected<PpmImage, std::string> readPpm(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return std::unexpected(path.string() + ": cannot open");
  }
  std::string magic;
  std::string w;
  std::string h;
  std::string maxval;
  if (!readPpmToken(in, magic) || magic != "P6") {
    return std::unexpected(path.string() + ": not a binary PPM (P6)");
  }
  PpmImage image;
  if (!readPpmToken(in, w) || !readPpmToken(in, h) || !parsePositive(w, 1 << 16, image.width) ||
      !parsePositive(h, 1 << 16, image.height)) {
    return std::unexpected(path.string() + ": bad PPM size");
  }
  int max = 0;
  if (!readPpmToken(in, maxval) || !parsePositive(maxval, 65535, max) || max != 255) {
    return std::unexpected(path.string() + ": PPM maxval must be 255 (8 bits per channel), got '" +
                           maxval + "'");
  }
  image.pixels.resize(static_cast<std::size_t>(image.width) *
                      static_cast<std::size_t>(image.height));
  const auto bytes = static_cast<std::streamsize>(image.pixels.size() * sizeof(algo::Rgb8));
  in.read(reinterpret_cast<char*>(image.pixels.data()), bytes);
  if (in.gcount() != bytes) {
    return std::unexpected(path.string() + ": truncated: " + std::to_string(in.gcount()) + " of " +
                           std::to_string(bytes) + " pixel bytes");
  }
  return image;
}

std::expected<void, std::string> writePpm(const std::filesystem::path& path,
                                          algo::ConstRgbView image) {
  std::ofstream out(path, std::ios::binary);
  out << "P6\n" << image.width() << ' ' << image.height() << "\n255\n";
  for (int y = 0; y < image.height(); ++y) {
    const auto row = image.row(y);
    out.write(reinterpret_cast<const char*>(row.data()),
              static_cast<std::streamsize>(row.size_bytes()));
  }
  if (!out) {
    return std::unexpected(path.string() + ": cannot write");
  }
  return {};
}

}  // namespace smx::test
