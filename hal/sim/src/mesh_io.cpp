#include "smx/sim/mesh_io.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <fstream>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <utility>
#include <vector>

namespace smx::sim {
namespace {

using Status = std::expected<void, std::string>;

// Far above what the renderer holds comfortably, and a bound on what a wrong path (a video,
// a disk image) costs before it is rejected.
constexpr std::uintmax_t kMaxMeshBytes = std::uintmax_t{1} << 30U;
constexpr std::uint64_t kMaxVertices = std::numeric_limits<std::uint32_t>::max();

std::unexpected<std::string> fail(std::string problem) {
  return std::unexpected(std::move(problem));
}

std::string lineTag(std::size_t line) {
  return "line " + std::to_string(line) + ": ";
}

// For messages: the input may be anything, so cut it short and keep it printable.
std::string shown(std::string_view s) {
  constexpr std::size_t kMaxShown = 40;
  std::string out = "\"";
  for (const char c : s.substr(0, kMaxShown)) {
    const auto byte = static_cast<unsigned char>(c);
    out += (byte < 0x20 || byte >= 0x7f) ? '?' : c;
  }
  return out + (s.size() > kMaxShown ? "...\"" : "\"");
}

std::string formatValue(double v) {
  std::array<char, 32> buf{};
  const auto r = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  return {buf.data(), r.ptr};
}

bool isSpace(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

bool isBlank(std::string_view s) {
  return std::all_of(s.begin(), s.end(), isSpace);
}

// Splits the next whitespace-separated token off `rest`; empty at the end.
std::string_view nextToken(std::string_view& rest) {
  std::size_t begin = 0;
  while (begin < rest.size() && isSpace(rest[begin])) {
    ++begin;
  }
  std::size_t end = begin;
  while (end < rest.size() && !isSpace(rest[end])) {
    ++end;
  }
  const std::string_view token = rest.substr(begin, end - begin);
  rest.remove_prefix(end);
  return token;
}

// A whole token as a number ("1.5", "-2e-3", "+4"); std::from_chars, not streams, for speed.
std::optional<double> parseNumber(std::string_view token) {
  if (token.size() > 1 && token.front() == '+' && token[1] != '-' && token[1] != '+') {
    token.remove_prefix(1);  // from_chars does not take a leading '+'
  }
  double v = 0;
  const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), v);
  if (ptr != token.data() + token.size() || token.empty()) {
    return std::nullopt;
  }
  if (ec == std::errc::result_out_of_range) {
    // from_chars leaves v alone; strtod gives ±inf or the underflowed value, which the caller
    // then judges like any other.
    return std::strtod(std::string(token).c_str(), nullptr);
  }
  return ec == std::errc{} ? std::optional(v) : std::nullopt;
}

// Vertices are stored as float: a coordinate must survive the conversion.
std::optional<std::string> coordinateProblem(const std::array<double, 3>& xyz) {
  constexpr std::array<std::string_view, 3> kAxes = {"x", "y", "z"};
  for (std::size_t i = 0; i < 3; ++i) {
    if (!std::isfinite(xyz[i])) {
      return std::string(kAxes[i]) + " is not a finite number (" + formatValue(xyz[i]) + ")";
    }
    if (std::abs(xyz[i]) > std::numeric_limits<float>::max()) {
      return std::string(kAxes[i]) + " = " + formatValue(xyz[i]) + " is too large for a float";
    }
  }
  return std::nullopt;
}

Eigen::Vector3f toVertex(const std::array<double, 3>& xyz) {
  return {static_cast<float>(xyz[0]), static_cast<float>(xyz[1]), static_cast<float>(xyz[2])};
}

// A polygon v0 v1 ... vn-1 becomes the fan (v0, vk, vk+1): exact for the convex faces scanners
// and modellers write.
void addFan(const std::vector<std::uint32_t>& polygon, Mesh& mesh) {
  for (std::size_t k = 1; k + 1 < polygon.size(); ++k) {
    mesh.triangles.push_back({polygon[0], polygon[k], polygon[k + 1]});
  }
}

// Walks text line by line ("\n" or "\r\n"), numbering lines from `firstLine`.
class Lines {
 public:
  Lines(std::string_view text, std::size_t firstLine) : rest_(text), next_(firstLine) {}

  bool next(std::string_view& line) {
    if (rest_.empty()) {
      return false;
    }
    const auto end = rest_.find('\n');
    line = rest_.substr(0, end);
    rest_.remove_prefix(end == std::string_view::npos ? rest_.size() : end + 1);
    if (!line.empty() && line.back() == '\r') {
      line.remove_suffix(1);
    }
    number_ = next_++;
    return true;
  }

  // Skips blank lines; false at the end of the text.
  bool nextNonBlank(std::string_view& line) {
    while (next(line)) {
      if (!isBlank(line)) {
        return true;
      }
    }
    return false;
  }

  [[nodiscard]] std::size_t number() const { return number_; }  // of the line last returned
  [[nodiscard]] std::string_view rest() const { return rest_; }

 private:
  std::string_view rest_;
  std::size_t next_;
  std::size_t number_ = 0;
};

// --- PLY ---

enum class PlyType : std::uint8_t {
  kInt8,
  kUint8,
  kInt16,
  kUint16,
  kInt32,
  kUint32,
  kFloat,
  kDouble
};

struct PlyTypeName {
  std::string_view name;
  PlyType type;
};

constexpr std::array<PlyTypeName, 16> kPlyTypeNames = {{
    {"char", PlyType::kInt8},
    {"uchar", PlyType::kUint8},
    {"short", PlyType::kInt16},
    {"ushort", PlyType::kUint16},
    {"int", PlyType::kInt32},
    {"uint", PlyType::kUint32},
    {"float", PlyType::kFloat},
    {"double", PlyType::kDouble},
    {"int8", PlyType::kInt8},
    {"uint8", PlyType::kUint8},
    {"int16", PlyType::kInt16},
    {"uint16", PlyType::kUint16},
    {"int32", PlyType::kInt32},
    {"uint32", PlyType::kUint32},
    {"float32", PlyType::kFloat},
    {"float64", PlyType::kDouble},
}};

std::optional<PlyType> plyType(std::string_view name) {
  for (const auto& entry : kPlyTypeNames) {
    if (entry.name == name) {
      return entry.type;
    }
  }
  return std::nullopt;
}

std::size_t sizeOf(PlyType type) {
  switch (type) {
    case PlyType::kInt8:
    case PlyType::kUint8:
      return 1;
    case PlyType::kInt16:
    case PlyType::kUint16:
      return 2;
    case PlyType::kInt32:
    case PlyType::kUint32:
    case PlyType::kFloat:
      return 4;
    case PlyType::kDouble:
      return 8;
  }
  return 1;
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::kFloat;    // the item type of a list
  std::optional<PlyType> countType;  // set for list properties
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::size_t line = 0;  // of its "element" line
  std::vector<PlyProperty> properties;
};

enum class PlyEncoding : std::uint8_t { kAscii, kLittleEndian, kBigEndian };

struct PlyHeader {
  PlyEncoding encoding = PlyEncoding::kAscii;
  std::vector<PlyElement> elements;
  std::string_view data;       // everything after the end_header line
  std::size_t dataLine = 0;    // line number of the first data line (ascii)
  std::size_t dataOffset = 0;  // byte offset of `data` in the file (binary)
};

// What the reader takes from the elements: positions, colours (point clouds) and the faces'
// vertex lists (meshes).
struct PlyLayout {
  std::size_t vertex = 0;           // element index
  std::vector<int> axisOf;          // per vertex property: 0, 1, 2 for x, y, z, else -1
  std::vector<int> colourOf;        // per vertex property: 0, 1, 2 for red, green, blue, else -1
  std::optional<std::size_t> face;  // element index; none for point clouds
  std::size_t indices = 0;          // property index of vertex_indices in the face element
  std::uint64_t vertexCount = 0;
};

enum class PlyUse : std::uint8_t { kMesh, kPoints };

constexpr std::string_view kPlyTypesHint =
    "PLY types: char, uchar, short, ushort, int, uint, float, double (or int8, uint8, int16, "
    "uint16, int32, uint32, float32, float64)";

std::expected<PlyProperty, std::string> readPlyProperty(std::string_view rest, std::size_t line) {
  const auto syntax = [&] {
    return fail(lineTag(line) +
                "expected \"property <type> <name>\" or \"property list <count type> <item "
                "type> <name>\"");
  };
  const auto typeOf = [&](std::string_view name) -> std::expected<PlyType, std::string> {
    if (const auto type = plyType(name)) {
      return *type;
    }
    return fail(lineTag(line) + "unknown property type " + shown(name) + "; " +
                std::string(kPlyTypesHint));
  };
  PlyProperty property;
  const auto first = nextToken(rest);
  if (first == "list") {
    const auto countName = nextToken(rest);
    const auto itemName = nextToken(rest);
    property.name = nextToken(rest);
    if (property.name.empty() || !isBlank(rest)) {
      return syntax();
    }
    const auto countType = typeOf(countName);
    if (!countType) {
      return std::unexpected(countType.error());
    }
    const auto itemType = typeOf(itemName);
    if (!itemType) {
      return std::unexpected(itemType.error());
    }
    property.countType = *countType;
    property.type = *itemType;
    return property;
  }
  property.name = nextToken(rest);
  if (first.empty() || property.name.empty() || !isBlank(rest)) {
    return syntax();
  }
  const auto type = typeOf(first);
  if (!type) {
    return std::unexpected(type.error());
  }
  property.type = *type;
  return property;
}

std::expected<PlyHeader, std::string> readPlyHeader(std::string_view bytes) {
  if (bytes.empty()) {
    return fail("not a PLY file: the file is empty");
  }
  Lines lines(bytes, 1);
  std::string_view line;
  lines.next(line);
  if (line.find_last_not_of(" \t") != 2 || !line.starts_with("ply")) {
    return fail(lineTag(1) + "not a PLY file: the first line must be \"ply\", got " + shown(line));
  }
  PlyHeader header;
  bool haveFormat = false;
  while (lines.next(line)) {
    const std::size_t n = lines.number();
    std::string_view rest = line;
    const auto keyword = nextToken(rest);
    if (keyword.empty() || keyword == "comment" || keyword == "obj_info") {
      continue;
    }
    if (keyword == "format") {
      const auto encoding = nextToken(rest);
      const auto version = nextToken(rest);
      const std::string unsupported =
          lineTag(n) + "unsupported PLY format " + shown(line) +
          "; supported: ascii 1.0, binary_little_endian 1.0, binary_big_endian 1.0";
      if (haveFormat) {
        return fail(lineTag(n) + "a second format line");
      }
      if (version != "1.0" || !isBlank(rest)) {
        return fail(unsupported);
      }
      if (encoding == "ascii") {
        header.encoding = PlyEncoding::kAscii;
      } else if (encoding == "binary_little_endian") {
        header.encoding = PlyEncoding::kLittleEndian;
      } else if (encoding == "binary_big_endian") {
        header.encoding = PlyEncoding::kBigEndian;
      } else {
        return fail(unsupported);
      }
      haveFormat = true;
      continue;
    }
    if (!haveFormat) {
      return fail(lineTag(n) + "expected the format line (e.g. \"format ascii 1.0\") before " +
                  shown(line));
    }
    if (keyword == "element") {
      PlyElement element;
      element.name = nextToken(rest);
      const auto count = nextToken(rest);
      if (element.name.empty() || count.empty() || !isBlank(rest)) {
        return fail(lineTag(n) + "expected \"element <name> <count>\", got " + shown(line));
      }
      const auto [ptr, ec] =
          std::from_chars(count.data(), count.data() + count.size(), element.count);
      if (ec != std::errc{} || ptr != count.data() + count.size()) {
        return fail(lineTag(n) + "the count of element " + shown(element.name) + ", " +
                    shown(count) + ", is not a non-negative integer");
      }
      for (const auto& other : header.elements) {
        if (other.name == element.name) {
          return fail(lineTag(n) + "a second element " + shown(element.name) +
                      " (the first is on line " + std::to_string(other.line) + ")");
        }
      }
      element.line = n;
      header.elements.push_back(std::move(element));
    } else if (keyword == "property") {
      if (header.elements.empty()) {
        return fail(lineTag(n) + "a property before any element");
      }
      auto property = readPlyProperty(rest, n);
      if (!property) {
        return std::unexpected(property.error());
      }
      auto& properties = header.elements.back().properties;
      if (std::any_of(properties.begin(), properties.end(),
                      [&](const PlyProperty& p) { return p.name == property->name; })) {
        return fail(lineTag(n) + "property " + shown(property->name) +
                    " appears twice in element " + shown(header.elements.back().name));
      }
      properties.push_back(std::move(*property));
    } else if (keyword == "end_header") {
      if (!isBlank(rest)) {
        return fail(lineTag(n) + "unexpected text after end_header: " + shown(rest));
      }
      header.data = lines.rest();
      header.dataLine = n + 1;
      header.dataOffset = bytes.size() - header.data.size();
      return header;
    } else {
      return fail(lineTag(n) + "unknown header keyword " + shown(keyword) +
                  "; expected comment, obj_info, element, property or end_header");
    }
  }
  return fail("the header has no end_header line (the file ends at line " +
              std::to_string(lines.number()) + ")");
}

std::expected<PlyLayout, std::string> plyLayout(const PlyHeader& header, PlyUse use) {
  PlyLayout layout;
  const auto find = [&](std::string_view name) {
    return std::find_if(header.elements.begin(), header.elements.end(),
                        [&](const PlyElement& e) { return e.name == name; });
  };
  const auto vertex = find("vertex");
  if (vertex == header.elements.end()) {
    return fail("the header declares no \"vertex\" element");
  }
  layout.vertex = static_cast<std::size_t>(vertex - header.elements.begin());
  layout.vertexCount = vertex->count;
  if (vertex->count > kMaxVertices) {
    return fail("the header declares " + std::to_string(vertex->count) + " vertices; at most " +
                std::to_string(kMaxVertices) + " are supported (32-bit indices)");
  }
  layout.axisOf.assign(vertex->properties.size(), -1);
  for (int axis = 0; axis < 3; ++axis) {
    const std::string_view name =
        std::array<std::string_view, 3>{"x", "y", "z"}[static_cast<std::size_t>(axis)];
    const auto it = std::find_if(vertex->properties.begin(), vertex->properties.end(),
                                 [&](const PlyProperty& p) { return p.name == name; });
    if (it == vertex->properties.end()) {
      return fail("element \"vertex\" (line " + std::to_string(vertex->line) +
                  ") has no property " + shown(name));
    }
    if (it->countType) {
      return fail("element \"vertex\" (line " + std::to_string(vertex->line) + "): property " +
                  shown(name) + " must be a single number, not a list");
    }
    layout.axisOf[static_cast<std::size_t>(it - vertex->properties.begin())] = axis;
  }
  layout.colourOf.assign(vertex->properties.size(), -1);
  const auto face = find("face");
  if (use == PlyUse::kPoints) {
    for (std::size_t p = 0; p < vertex->properties.size(); ++p) {
      const auto& name = vertex->properties[p].name;
      const int channel = name == "red" ? 0 : name == "green" ? 1 : name == "blue" ? 2 : -1;
      if (channel >= 0 && vertex->properties[p].countType) {
        return fail("element \"vertex\" (line " + std::to_string(vertex->line) + "): property " +
                    shown(name) + " must be a single number, not a list");
      }
      layout.colourOf[p] = channel;
    }
    if (face != header.elements.end()) {
      return fail("element \"face\" (line " + std::to_string(face->line) +
                  "): a point cloud has no faces; this is a mesh");
    }
    return layout;
  }
  if (face == header.elements.end()) {
    return fail(
        "the header declares no \"face\" element: a point cloud has no triangles to render");
  }
  layout.face = static_cast<std::size_t>(face - header.elements.begin());
  const auto indices = std::find_if(
      face->properties.begin(), face->properties.end(),
      [](const PlyProperty& p) { return p.name == "vertex_indices" || p.name == "vertex_index"; });
  if (indices == face->properties.end() || !indices->countType) {
    return fail("element \"face\" (line " + std::to_string(face->line) +
                R"() has no list property "vertex_indices" or "vertex_index")");
  }
  layout.indices = static_cast<std::size_t>(indices - face->properties.begin());
  return layout;
}

// A colour channel as PLY stores it (uchar): 0..255, whatever the declared type.
std::optional<std::uint8_t> channelValue(double v) {
  if (v < 0 || v > 255 || v != std::floor(v)) {  // NaN too: NaN != NaN
    return std::nullopt;
  }
  return static_cast<std::uint8_t>(v);
}

// The least number of bytes one row can take: bounds reservations by what the file can hold.
std::size_t minRowBytes(const PlyElement& element, PlyEncoding encoding) {
  std::size_t bytes = 0;
  for (const auto& p : element.properties) {
    bytes += encoding == PlyEncoding::kAscii ? 2 : sizeOf(p.countType.value_or(p.type));
  }
  return std::max<std::size_t>(bytes, 1);
}

enum class Read : std::uint8_t { kOk, kEnd, kBad };

template <class T>
T loadAs(const char* p, bool swap) {
  if constexpr (sizeof(T) == 1) {
    T v{};
    std::memcpy(&v, p, 1);
    return v;
  } else {
    using Bits =
        std::conditional_t<sizeof(T) == 2, std::uint16_t,
                           std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>>;
    Bits bits{};
    std::memcpy(&bits, p, sizeof(Bits));
    return std::bit_cast<T>(swap ? std::byteswap(bits) : bits);
  }
}

double decode(const char* p, PlyType type, bool swap) {
  switch (type) {
    case PlyType::kInt8:
      return loadAs<std::int8_t>(p, swap);
    case PlyType::kUint8:
      return loadAs<std::uint8_t>(p, swap);
    case PlyType::kInt16:
      return loadAs<std::int16_t>(p, swap);
    case PlyType::kUint16:
      return loadAs<std::uint16_t>(p, swap);
    case PlyType::kInt32:
      return loadAs<std::int32_t>(p, swap);
    case PlyType::kUint32:
      return loadAs<std::uint32_t>(p, swap);
    case PlyType::kFloat:
      return loadAs<float>(p, swap);
    case PlyType::kDouble:
      return loadAs<double>(p, swap);
  }
  return 0;
}

// Binary rows: values back to back, each in the file's byte order.
class BinarySource {
 public:
  BinarySource(std::string_view data, std::size_t fileOffset, bool bigEndian)
      : data_(data),
        fileOffset_(fileOffset),
        swap_(bigEndian != (std::endian::native == std::endian::big)) {}

  bool beginRow() {
    rowStart_ = pos_;
    return true;  // a short file shows up at the first value that is missing
  }

  Read read(PlyType type, double& out) {
    const std::size_t size = sizeOf(type);
    if (data_.size() - pos_ < size) {
      return Read::kEnd;
    }
    out = decode(data_.data() + pos_, type, swap_);
    pos_ += size;
    return Read::kOk;
  }

  // "face 3 (byte 1234)": where a problem is.
  [[nodiscard]] std::string at(const std::string& row) const {
    return row + " (byte " + std::to_string(fileOffset_ + rowStart_) + ")";
  }

  [[nodiscard]] std::string problem(Read r, const std::string& row,
                                    std::string_view property) const {
    (void)r;  // only kEnd happens in binary data
    return at(row) + ": the file ends before property " + shown(property) +
           "; it is truncated or the header declares too many elements";
  }

  static std::string endedBefore(const std::string& row, const PlyElement& element) {
    return "the file ends before " + row + " of the " + std::to_string(element.count) +
           " the header declares";
  }

  static Status endRow(const std::string& /*row*/, const PlyElement& /*element*/) { return {}; }

  [[nodiscard]] Status finish() const {
    if (pos_ != data_.size()) {
      return fail(std::to_string(data_.size() - pos_) +
                  " bytes of unexpected data after the last element (from byte " +
                  std::to_string(fileOffset_ + pos_) +
                  "); the header declares fewer elements than the file holds");
    }
    return {};
  }

 private:
  std::string_view data_;
  std::size_t fileOffset_;
  bool swap_;
  std::size_t pos_ = 0;
  std::size_t rowStart_ = 0;
};

// ASCII rows: one element per line, values separated by blanks.
class AsciiSource {
 public:
  AsciiSource(std::string_view data, std::size_t firstLine) : lines_(data, firstLine) {}

  bool beginRow() { return lines_.nextNonBlank(rest_); }

  Read read(PlyType /*type*/, double& out) {
    token_ = nextToken(rest_);
    if (token_.empty()) {
      return Read::kEnd;
    }
    const auto v = parseNumber(token_);
    if (!v) {
      return Read::kBad;
    }
    out = *v;
    return Read::kOk;
  }

  [[nodiscard]] std::string at(const std::string& row) const {
    return lineTag(lines_.number()) + row;
  }

  [[nodiscard]] std::string problem(Read r, const std::string& row,
                                    std::string_view property) const {
    if (r == Read::kEnd) {
      return at(row) + ": the line ends before property " + shown(property);
    }
    return at(row) + ": property " + shown(property) + ": " + shown(token_) + " is not a number";
  }

  [[nodiscard]] std::string endedBefore(const std::string& row, const PlyElement& element) const {
    return lineTag(lines_.number()) + "the file ends before " + row + " of the " +
           std::to_string(element.count) + " the header declares";
  }

  Status endRow(const std::string& row, const PlyElement& element) {
    if (const auto extra = nextToken(rest_); !extra.empty()) {
      return fail(at(row) + ": more values than element " + shown(element.name) + " declares (" +
                  shown(extra) + " after the last property, " +
                  shown(element.properties.empty() ? "" : element.properties.back().name) + ")");
    }
    return {};
  }

  Status finish() {
    std::string_view line;
    if (lines_.nextNonBlank(line)) {
      return fail(lineTag(lines_.number()) + "unexpected data after the last element: " +
                  shown(line) + "; the header declares fewer elements than the file holds");
    }
    return {};
  }

 private:
  Lines lines_;
  std::string_view rest_;
  std::string_view token_;
};

bool isWholeNonNegative(double v) {
  return v >= 0 && v == std::floor(v);
}

// Longer lists cannot fit in a file of kMaxMeshBytes; the bound also makes the cast safe.
constexpr double kMaxListLength = std::numeric_limits<std::uint32_t>::max();

std::string vertexCountText(std::uint64_t count) {
  return count == 0 ? std::string("no vertices")
                    : std::to_string(count) + " vertices (0 to " + std::to_string(count - 1) + ")";
}

// Fills mesh.vertices and mesh.triangles, and with `colours` a colour per vertex.
template <class Source>
Status readPlyData(Source& source, const PlyHeader& header, const PlyLayout& layout, Mesh& mesh,
                   std::vector<std::array<std::uint8_t, 3>>* colours) {
  std::vector<std::uint32_t> polygon;
  for (std::size_t e = 0; e < header.elements.size(); ++e) {
    const PlyElement& element = header.elements[e];
    const bool isVertex = e == layout.vertex;
    const bool isFace = layout.face && e == *layout.face;
    const std::size_t maxRows = header.data.size() / minRowBytes(element, header.encoding);
    const auto reserve = static_cast<std::size_t>(std::min<std::uint64_t>(element.count, maxRows));
    if (isVertex) {
      mesh.vertices.reserve(reserve);
      if (colours != nullptr) {
        colours->reserve(reserve);
      }
    } else if (isFace) {
      mesh.triangles.reserve(reserve);
    }
    for (std::uint64_t row = 0; row < element.count; ++row) {
      const auto rowName = [&] { return element.name + " " + std::to_string(row); };
      if (!source.beginRow()) {
        return fail(source.endedBefore(rowName(), element));
      }
      std::array<double, 3> xyz{};
      std::array<std::uint8_t, 3> rgb{};
      for (std::size_t p = 0; p < element.properties.size(); ++p) {
        const PlyProperty& property = element.properties[p];
        double value = 0;
        if (!property.countType) {
          if (const Read r = source.read(property.type, value); r != Read::kOk) {
            return fail(source.problem(r, rowName(), property.name));
          }
          if (isVertex && layout.axisOf[p] >= 0) {
            xyz[static_cast<std::size_t>(layout.axisOf[p])] = value;
          }
          if (isVertex && colours != nullptr && layout.colourOf[p] >= 0) {
            const auto channel = channelValue(value);
            if (!channel) {
              return fail(source.at(rowName()) + ": colour " + shown(property.name) + " = " +
                          formatValue(value) + " is not an integer 0..255");
            }
            rgb[static_cast<std::size_t>(layout.colourOf[p])] = *channel;
          }
          continue;
        }
        if (const Read r = source.read(*property.countType, value); r != Read::kOk) {
          return fail(source.problem(r, rowName(), property.name));
        }
        if (!isWholeNonNegative(value) || value > kMaxListLength) {
          return fail(source.at(rowName()) + ": the length of list " + shown(property.name) +
                      " is " + formatValue(value) + ", not a non-negative 32-bit integer");
        }
        const auto length = static_cast<std::uint64_t>(value);
        const bool isPolygon = isFace && p == layout.indices;
        if (isPolygon && length < 3) {
          return fail(source.at(rowName()) + " has " + std::to_string(length) +
                      " vertices; a face needs at least 3");
        }
        polygon.clear();
        for (std::uint64_t k = 0; k < length; ++k) {
          if (const Read r = source.read(property.type, value); r != Read::kOk) {
            return fail(source.problem(r, rowName(), property.name));
          }
          if (!isPolygon) {
            continue;
          }
          if (!isWholeNonNegative(value)) {
            return fail(source.at(rowName()) + ": vertex index " + formatValue(value) +
                        " is not a non-negative integer");
          }
          if (value >= static_cast<double>(layout.vertexCount)) {
            return fail(source.at(rowName()) + " refers to vertex " + formatValue(value) +
                        ", but the file has " + vertexCountText(layout.vertexCount));
          }
          polygon.push_back(static_cast<std::uint32_t>(value));
        }
        if (isPolygon) {
          addFan(polygon, mesh);
        }
      }
      if (auto s = source.endRow(rowName(), element); !s) {
        return s;
      }
      if (isVertex) {
        if (const auto problem = coordinateProblem(xyz)) {
          return fail(source.at(rowName()) + ": " + *problem);
        }
        mesh.vertices.push_back(toVertex(xyz));
        if (colours != nullptr) {
          colours->push_back(rgb);
        }
      }
    }
  }
  return source.finish();
}

// The one PLY reader: meshes (kMesh: faces required, colour ignored) and point clouds (kPoints:
// no faces, colour read into `colours`).
Status parsePlyInto(std::string_view bytes, PlyUse use, Mesh& mesh,
                    std::vector<std::array<std::uint8_t, 3>>* colours) {
  const auto header = readPlyHeader(bytes);
  if (!header) {
    return std::unexpected(header.error());
  }
  const auto layout = plyLayout(*header, use);
  if (!layout) {
    return std::unexpected(layout.error());
  }
  if (header->encoding == PlyEncoding::kAscii) {
    AsciiSource source(header->data, header->dataLine);
    return readPlyData(source, *header, *layout, mesh, colours);
  }
  BinarySource source(header->data, header->dataOffset,
                      header->encoding == PlyEncoding::kBigEndian);
  return readPlyData(source, *header, *layout, mesh, colours);
}

std::expected<Mesh, std::string> parsePly(std::string_view bytes) {
  Mesh mesh;
  if (auto read = parsePlyInto(bytes, PlyUse::kMesh, mesh, nullptr); !read) {
    return std::unexpected(read.error());
  }
  if (mesh.triangles.empty()) {
    return fail("no triangles: the \"face\" element is empty");
  }
  return mesh;
}

// --- OBJ ---

bool isInteger(std::string_view s) {
  long long v = 0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  return !s.empty() && ec == std::errc{} && ptr == s.data() + s.size();
}

// "7", "7/3", "7//2" or "7/3/2" (texture and normal indices are checked for form only).
std::optional<long long> vertexReference(std::string_view token) {
  const auto slash = token.find('/');
  const std::string_view head = token.substr(0, slash);
  long long index = 0;
  const auto [ptr, ec] = std::from_chars(head.data(), head.data() + head.size(), index);
  if (head.empty() || ec != std::errc{} || ptr != head.data() + head.size()) {
    return std::nullopt;
  }
  if (slash == std::string_view::npos) {
    return index;
  }
  const std::string_view tail = token.substr(slash + 1);
  const auto second = tail.find('/');
  if (second == std::string_view::npos) {
    return isInteger(tail) ? std::optional(index) : std::nullopt;  // i/t
  }
  const std::string_view texture = tail.substr(0, second);
  const std::string_view normal = tail.substr(second + 1);
  return (texture.empty() || isInteger(texture)) && isInteger(normal) ? std::optional(index)
                                                                      : std::nullopt;
}

std::expected<Mesh, std::string> parseObj(std::string_view text) {
  Mesh mesh;
  Lines lines(text, 1);
  std::string_view line;
  std::vector<std::uint32_t> polygon;
  // Positive indices may point forward (to vertices defined later); they are checked at the end.
  long long maxIndex = 0;
  std::size_t maxIndexLine = 0;
  while (lines.next(line)) {
    const std::size_t n = lines.number();
    line = line.substr(0, line.find('#'));
    std::string_view rest = line;
    const auto keyword = nextToken(rest);
    if (keyword == "v") {
      std::array<double, 3> xyz{};
      std::size_t count = 0;
      // "v x y z [w]"; tools that append vertex colours write more numbers, which are skipped.
      for (auto token = nextToken(rest); !token.empty(); token = nextToken(rest)) {
        const auto v = parseNumber(token);
        if (!v) {
          return fail(lineTag(n) + "vertex: " + shown(token) + " is not a number");
        }
        if (count < 3) {
          xyz[count] = *v;
        }
        ++count;
      }
      if (count < 3) {
        return fail(lineTag(n) + "a vertex needs 3 coordinates (v x y z), got " +
                    std::to_string(count));
      }
      if (const auto problem = coordinateProblem(xyz)) {
        return fail(lineTag(n) + "vertex: " + *problem);
      }
      if (mesh.vertices.size() >= kMaxVertices) {
        return fail(lineTag(n) + "more than " + std::to_string(kMaxVertices) +
                    " vertices (32-bit indices)");
      }
      mesh.vertices.push_back(toVertex(xyz));
    } else if (keyword == "f") {
      polygon.clear();
      const auto defined = static_cast<long long>(mesh.vertices.size());
      for (auto token = nextToken(rest); !token.empty(); token = nextToken(rest)) {
        const auto index = vertexReference(token);
        if (!index) {
          return fail(lineTag(n) + "face: " + shown(token) +
                      " is not a vertex reference (i, i/t, i//n or i/t/n)");
        }
        if (*index == 0) {
          return fail(lineTag(n) +
                      "face: vertex index 0 is invalid (OBJ indices start at 1; negative ones "
                      "count back from the last vertex)");
        }
        if (*index < 0 && -*index > defined) {
          return fail(lineTag(n) + "face: vertex index " + std::to_string(*index) +
                      " reaches back past the first vertex (" + std::to_string(defined) +
                      " defined so far)");
        }
        if (*index > maxIndex) {
          maxIndex = *index;
          maxIndexLine = n;
        }
        const long long zeroBased = *index < 0 ? defined + *index : *index - 1;
        polygon.push_back(static_cast<std::uint32_t>(
            std::min<long long>(zeroBased, std::numeric_limits<std::uint32_t>::max())));
      }
      if (polygon.size() < 3) {
        return fail(lineTag(n) + "a face needs at least 3 vertices, got " +
                    std::to_string(polygon.size()));
      }
      addFan(polygon, mesh);
    }
    // Everything else (vt, vn, g, o, s, usemtl, mtllib, l, p, ...) does not shape the surface.
  }
  if (maxIndex > static_cast<long long>(mesh.vertices.size())) {
    return fail(lineTag(maxIndexLine) + "face refers to vertex " + std::to_string(maxIndex) +
                ", but the file has " + std::to_string(mesh.vertices.size()) + " vertices");
  }
  if (mesh.triangles.empty()) {
    return fail("no triangles: the file has no faces (\"f\" lines)");
  }
  return mesh;
}

// --- files ---

std::expected<std::string, std::string> readFile(const std::filesystem::path& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) {
    return fail("cannot read the file: " + (ec ? ec.message() : std::string("no such file")));
  }
  if (!std::filesystem::is_regular_file(status)) {
    return fail("cannot read the file: it is not a regular file");
  }
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) {
    return fail("cannot read the file: " + ec.message());
  }
  if (size > kMaxMeshBytes) {
    return fail("the file is " + std::to_string(size) + " bytes; files of at most " +
                std::to_string(kMaxMeshBytes) + " bytes are read");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return fail("cannot read the file: " +
                std::generic_category().message(errno != 0 ? errno : EIO));
  }
  std::string bytes(static_cast<std::size_t>(size), '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (static_cast<std::uintmax_t>(in.gcount()) != size) {
    return fail("cannot read the file: read error");
  }
  return bytes;
}

std::expected<Mesh, MeshError> parseImpl(std::string_view bytes, MeshFormat format) {
  auto mesh = format == MeshFormat::kPly ? parsePly(bytes) : parseObj(bytes);
  if (!mesh) {
    return std::unexpected(MeshError{{}, std::move(mesh.error())});
  }
  return std::move(*mesh);
}

}  // namespace

std::string MeshError::message() const {
  return file.empty() ? problem : file + ": " + problem;
}

std::expected<Mesh, MeshError> parseMesh(std::string_view bytes, MeshFormat format) {
  try {
    return parseImpl(bytes, format);
  } catch (const std::exception& e) {
    // Out of memory or a library surprise: still an error value, never an exception.
    return std::unexpected(MeshError{{}, std::string("cannot read the mesh: ") + e.what()});
  }
}

std::expected<Mesh, MeshError> loadMesh(const std::filesystem::path& path) {
  const auto withFile = [&](std::string problem) {
    return std::unexpected(MeshError{path.string(), std::move(problem)});
  };
  try {
    std::string extension = path.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    MeshFormat format = MeshFormat::kPly;
    if (extension == ".obj") {
      format = MeshFormat::kObj;
    } else if (extension != ".ply") {
      return withFile((extension.empty() ? std::string("the file name has no extension")
                                         : "unknown mesh file extension " + shown(extension)) +
                      "; meshes are PLY (.ply) or Wavefront OBJ (.obj)");
    }
    auto bytes = readFile(path);
    if (!bytes) {
      return withFile(std::move(bytes.error()));
    }
    auto mesh = parseImpl(*bytes, format);
    if (!mesh) {
      return withFile(std::move(mesh.error().problem));
    }
    mesh->path = path.string();
    return mesh;
  } catch (const std::exception& e) {
    return withFile(std::string("cannot read the mesh: ") + e.what());
  }
}

std::expected<std::vector<PlyPoint>, std::string> readPlyPoints(const std::filesystem::path& path) {
  const auto withFile = [&](const std::string& problem) {
    return std::unexpected(path.string() + ": " + problem);
  };
  try {
    const auto bytes = readFile(path);
    if (!bytes) {
      return withFile(bytes.error());
    }
    Mesh cloud;
    std::vector<std::array<std::uint8_t, 3>> colours;
    if (auto read = parsePlyInto(*bytes, PlyUse::kPoints, cloud, &colours); !read) {
      return withFile(read.error());
    }
    std::vector<PlyPoint> points(cloud.vertices.size());
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3f& v = cloud.vertices[i];
      points[i] = {v.x(), v.y(), v.z(), colours[i][0], colours[i][1], colours[i][2]};
    }
    return points;
  } catch (const std::exception& e) {
    return withFile(std::string("cannot read the point cloud: ") + e.what());
  }
}

}  // namespace smx::sim
