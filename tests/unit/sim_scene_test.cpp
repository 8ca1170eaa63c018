// scene.json (`stripemux-scene/1`) and the mesh files it names: reading, defaults, the rotation
// convention, path resolution, the validation rules with their messages, and the shipped meshes.
// Formats: docs/scene-format.md.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <string>
#include <string_view>
#include <type_traits>
#include <variant>
#include <vector>

#include "smx/config/scene_json.hpp"
#include "smx/sim/mesh_io.hpp"
#include "smx/sim/png_io.hpp"
#include "smx/sim/scene.hpp"
#include "source_dir.hpp"

namespace smx::sim {
namespace {

namespace fs = std::filesystem;
using config::loadScene;
using config::parseScene;
using Triangle = std::array<std::uint32_t, 3>;

const fs::path kSourceDir = smx::test::sourceDir();
const fs::path kTestData = kSourceDir / "tests/unit/testdata";
const fs::path kShippedMeshes = kSourceDir / "hal/sim/scenes/meshes";

bool contains(std::string_view text, std::string_view part) {
  return text.find(part) != std::string_view::npos;
}

// A fresh directory per test, for files a test writes.
fs::path tempDir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const fs::path dir = fs::temp_directory_path() / (std::string("smx_sim_scene_") +
                                                    info->test_suite_name() + "_" + info->name());
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void writeFile(const fs::path& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  ASSERT_TRUE(out.good()) << path;
}

// Every scene key with a value that differs from its default, so that each can be replaced by
// text substitution and every index in an error path means something. Objects 0-3 are the four
// primitive shapes, object 4 the OBJ fixture (relative to tests/unit/testdata/meshes).
constexpr std::string_view kValidScene = R"({
  "format": "stripemux-scene/1",
  "supersampling": 3,
  "lighting": {"ambient": [0.01, 0.02, 0.04], "projector_power": 0.75, "inverse_square": true,
               "reference_distance_m": 1.25, "projector_defocus_sigma_px": 0.5,
               "projector_black_level": 0.01, "projector_gamma": 2.2},
  "camera_response": {"crosstalk": [0.9, 0.05, 0.01, 0.04, 0.85, 0.06, 0.02, 0.07, 0.8],
                      "gain": 1.5, "noise_sigma": [2, 1.5, 0.25], "defocus_sigma_px": 0.75,
                      "response_gamma": 1.8, "vignetting": 0.3, "bayer": "grbg",
                      "exposure": 0.5, "exposure_samples": 5},
  "objects": [
    {"name": "wall", "shape": {"type": "plane", "width_m": 1.2, "height_m": 0.9},
     "pose": {"t": [0, 0, 1.1]},
     "albedo": {"checker": {"square_m": 0.05, "colours": [[1, 0, 0], [0, 0.5, 1]]}}},
    {"name": "crate", "shape": {"type": "box", "size_m": [0.1, 0.2, 0.3]},
     "pose": {"t": [0.1, -0.2, 0.9], "R": [0, -1, 0, 1, 0, 0, 0, 0, 1], "scale": 2},
     "motion": {"velocity_m_per_frame": [0.001, 0, -0.002], "axis": [0, 0, 2],
                "angular_deg_per_frame": 1.5, "pivot": [0.15, -0.25, 0.95]},
     "albedo": {"rgb": [0.2, 0.4, 0.6]}},
    {"name": "ball", "shape": {"type": "sphere", "radius_m": 0.07},
     "pose": {"rotation_deg": [0, 90, 0]},
     "albedo": {"rgb": [0.5, 0.5, 0.5], "specular": 0.4, "shininess": 120}},
    {"shape": {"type": "cylinder", "radius_m": 0.03, "height_m": 0.25, "capped": false}},
    {"name": "square", "shape": {"type": "mesh", "path": "square.obj"}}
  ]
})";

const fs::path kValidSceneDir = kTestData / "meshes";

// kValidScene with the one occurrence of `from` replaced by `to`.
std::string validSceneWith(std::string_view from, std::string_view to) {
  std::string text(kValidScene);
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "test bug: " << from << " not in kValidScene";
  EXPECT_EQ(text.find(from, at + 1), std::string::npos) << "test bug: " << from << " not unique";
  if (at != std::string::npos) {
    text.replace(at, from.size(), to);
  }
  return text;
}

// A scene whose objects array is `objects`.
std::string sceneWithObjects(std::string_view objects) {
  return R"({"format": "stripemux-scene/1", "objects": )" + std::string(objects) + "}";
}

// Parses `text`, expects it to be rejected for `field`, with a problem mentioning each of `parts`.
void expectRejected(std::string_view text, std::string_view field,
                    std::initializer_list<std::string_view> parts,
                    const fs::path& baseDir = kValidSceneDir) {
  const auto scene = parseScene(text, baseDir);
  ASSERT_FALSE(scene.has_value()) << "accepted:\n" << text;
  EXPECT_EQ(scene.error().field, field) << scene.error().message();
  for (const auto part : parts) {
    EXPECT_TRUE(contains(scene.error().problem, part))
        << "problem \"" << scene.error().problem << "\" lacks \"" << part << "\"";
  }
  EXPECT_TRUE(scene.error().file.empty());
}

void expectMatrix(const Mat3& actual, const std::array<double, 9>& rowMajor, double tolerance) {
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      EXPECT_NEAR(actual(i, j), rowMajor[static_cast<std::size_t>(3 * i + j)], tolerance)
          << "R(" << i << ", " << j << ")\n"
          << actual;
    }
  }
}

void expectMesh(const Mesh& mesh, const std::vector<std::array<float, 3>>& vertices,
                const std::vector<Triangle>& triangles) {
  ASSERT_EQ(mesh.vertices.size(), vertices.size());
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    EXPECT_EQ(mesh.vertices[i].x(), vertices[i][0]) << "vertex " << i;
    EXPECT_EQ(mesh.vertices[i].y(), vertices[i][1]) << "vertex " << i;
    EXPECT_EQ(mesh.vertices[i].z(), vertices[i][2]) << "vertex " << i;
  }
  EXPECT_EQ(mesh.triangles, triangles);
}

// The square fixtures: a unit quad with a triangle on top.
const std::vector<std::array<float, 3>> kSquareVertices = {
    {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0.25F}, {0.5F, 1.5F, -1e-3F}};

// Expects parseMesh to reject `bytes` with a problem mentioning each of `parts`.
void expectMeshRejected(std::string_view bytes, MeshFormat format,
                        std::initializer_list<std::string_view> parts) {
  const auto mesh = parseMesh(bytes, format);
  ASSERT_FALSE(mesh.has_value()) << "accepted:\n" << bytes;
  for (const auto part : parts) {
    EXPECT_TRUE(contains(mesh.error().problem, part))
        << "problem \"" << mesh.error().problem << "\" lacks \"" << part << "\"";
  }
  EXPECT_TRUE(mesh.error().file.empty());
}

// Writes binary PLY values byte by byte in the chosen order (independent of the loader's
// memcpy/byteswap).
class PlyBytes {
 public:
  explicit PlyBytes(bool bigEndian) : bigEndian_(bigEndian) {}

  PlyBytes& text(std::string_view s) {
    bytes_ += s;
    return *this;
  }

  template <class T>
  PlyBytes& put(T v) {
    std::uint64_t bits = 0;
    if constexpr (std::is_same_v<T, float>) {
      bits = std::bit_cast<std::uint32_t>(v);
    } else if constexpr (std::is_same_v<T, double>) {
      bits = std::bit_cast<std::uint64_t>(v);
    } else {
      bits = static_cast<std::make_unsigned_t<T>>(v);
    }
    for (std::size_t i = 0; i < sizeof(T); ++i) {
      const std::size_t shift = 8 * (bigEndian_ ? sizeof(T) - 1 - i : i);
      bytes_ += static_cast<char>((bits >> shift) & 0xFFU);
    }
    return *this;
  }

  [[nodiscard]] const std::string& bytes() const { return bytes_; }

 private:
  bool bigEndian_;
  std::string bytes_;
};

// Big-endian, x/y/z of three different types (one an integer type), skipped scalars before and
// after a list property in the vertex element, extra face properties and an extra element.
std::string bigEndianFixture() {
  PlyBytes b(true);
  b.text(
      "ply\nformat binary_big_endian 1.0\n"
      "element vertex 4\n"
      "property double x\nproperty float y\nproperty short z\nproperty uchar red\n"
      "property list uchar int16 extra\nproperty ushort flags\n"
      "element face 2\n"
      "property uint8 flags\nproperty list uint8 uint32 vertex_indices\n"
      "property list int16 float texcoord\n"
      "element material 1\nproperty int id\n"
      "end_header\n");
  // x, y, z, red, extra list, flags
  b.put(0.5).put(-1.25F).put<std::int16_t>(3).put<std::uint8_t>(200);
  b.put<std::uint8_t>(2).put<std::int16_t>(1).put<std::int16_t>(-2).put<std::uint16_t>(65535);
  b.put(2.0).put(0.0F).put<std::int16_t>(-4).put<std::uint8_t>(0);
  b.put<std::uint8_t>(0).put<std::uint16_t>(7);
  b.put(-0.125).put(8.5F).put<std::int16_t>(0).put<std::uint8_t>(9);
  b.put<std::uint8_t>(1).put<std::int16_t>(5).put<std::uint16_t>(1);
  b.put(0.75).put(1.5F).put<std::int16_t>(300).put<std::uint8_t>(1);
  b.put<std::uint8_t>(3).put<std::int16_t>(0).put<std::int16_t>(0).put<std::int16_t>(0);
  b.put<std::uint16_t>(2);
  // faces: flags, vertex_indices, texcoord
  b.put<std::uint8_t>(1).put<std::uint8_t>(3).put<std::uint32_t>(0).put<std::uint32_t>(1);
  b.put<std::uint32_t>(2).put<std::int16_t>(2).put(0.5F).put(0.5F);
  b.put<std::uint8_t>(0).put<std::uint8_t>(4).put<std::uint32_t>(1).put<std::uint32_t>(3);
  b.put<std::uint32_t>(2).put<std::uint32_t>(0).put<std::int16_t>(0);
  b.put<std::int32_t>(42);  // material
  return b.bytes();
}

// Little-endian, integer coordinates of three widths, a list of doubles in the vertex element,
// an element before the vertices, the `vertex_index` spelling with an int32 count and int8
// indices.
std::string littleEndianFixture(std::int8_t lastIndex = 1) {
  PlyBytes b(false);
  b.text(
      "ply\r\nformat binary_little_endian 1.0\r\ncomment CRLF header lines\r\n"
      "element camera 1\r\nproperty float32 fov\r\nproperty list uint8 uint8 name\r\n"
      "element vertex 3\r\n"
      "property int8 x\r\nproperty uint16 y\r\nproperty int32 z\r\nproperty float32 nx\r\n"
      "property list uint16 float64 weights\r\n"
      "element face 1\r\nproperty list int32 int8 vertex_index\r\n"
      "end_header\r\n");
  b.put(0.9F).put<std::uint8_t>(2).put<std::uint8_t>('c').put<std::uint8_t>('0');
  b.put<std::int8_t>(-5).put<std::uint16_t>(60000).put<std::int32_t>(-70000).put(0.5F);
  b.put<std::uint16_t>(1).put(0.25);
  b.put<std::int8_t>(127).put<std::uint16_t>(0).put<std::int32_t>(1).put(1.0F);
  b.put<std::uint16_t>(0);
  b.put<std::int8_t>(-128).put<std::uint16_t>(1).put<std::int32_t>(123456).put(0.0F);
  b.put<std::uint16_t>(2).put(1.0).put(2.0);
  b.put<std::int32_t>(3).put<std::int8_t>(2).put<std::int8_t>(0).put(lastIndex);
  return b.bytes();
}

// ---------------------------------------------------------------------------------------------
// Reading valid scenes

// Given the valid scene text, when parsed, then every field lands in the matching member.
TEST(SceneJson, ValidSceneIsReadFieldByField) {
  const auto scene = parseScene(kValidScene, kValidSceneDir);
  ASSERT_TRUE(scene.has_value()) << scene.error().message();
  EXPECT_EQ(scene->supersampling, 3);
  EXPECT_EQ(scene->lighting.ambient, Vec3(0.01, 0.02, 0.04));
  EXPECT_EQ(scene->lighting.projectorPower, 0.75);
  EXPECT_TRUE(scene->lighting.inverseSquare);
  EXPECT_EQ(scene->lighting.referenceDistanceM, 1.25);
  EXPECT_EQ(scene->lighting.projectorDefocusSigmaPx, 0.5);
  EXPECT_EQ(scene->lighting.projectorBlackLevel, 0.01);
  EXPECT_EQ(scene->lighting.projectorGamma, 2.2);
  Mat3 crosstalk;
  crosstalk << 0.9, 0.05, 0.01, 0.04, 0.85, 0.06, 0.02, 0.07, 0.8;
  EXPECT_EQ(scene->camera.crosstalk, crosstalk);
  EXPECT_EQ(scene->camera.crosstalk(0, 1), 0.05);  // row-major: row 0 is camera red
  EXPECT_EQ(scene->camera.gain, 1.5);
  EXPECT_EQ(scene->camera.noiseSigma, Vec3(2, 1.5, 0.25));
  EXPECT_EQ(scene->camera.defocusSigmaPx, 0.75);
  EXPECT_EQ(scene->camera.responseGamma, 1.8);
  EXPECT_EQ(scene->camera.vignetting, 0.3);
  EXPECT_EQ(scene->camera.bayer, "grbg");
  EXPECT_EQ(scene->camera.exposure, 0.5);
  EXPECT_EQ(scene->camera.exposureSamples, 5);

  ASSERT_EQ(scene->objects.size(), 5U);
  const Object& wall = scene->objects[0];
  EXPECT_EQ(wall.name, "wall");
  ASSERT_TRUE(std::holds_alternative<Plane>(wall.shape));
  EXPECT_EQ(std::get<Plane>(wall.shape).widthM, 1.2);
  EXPECT_EQ(std::get<Plane>(wall.shape).heightM, 0.9);
  EXPECT_EQ(wall.pose.t, Vec3(0, 0, 1.1));
  ASSERT_TRUE(std::holds_alternative<CheckerTexture>(wall.albedo.texture));
  const auto& checker = std::get<CheckerTexture>(wall.albedo.texture);
  EXPECT_EQ(checker.squareM, 0.05);
  EXPECT_EQ(checker.colours, (std::vector<Vec3>{{1, 0, 0}, {0, 0.5, 1}}));

  const Object& crate = scene->objects[1];
  EXPECT_EQ(crate.name, "crate");
  ASSERT_TRUE(std::holds_alternative<Box>(crate.shape));
  EXPECT_EQ(std::get<Box>(crate.shape).sizeM, Vec3(0.1, 0.2, 0.3));
  EXPECT_EQ(crate.pose.t, Vec3(0.1, -0.2, 0.9));
  expectMatrix(crate.pose.R, {0, -1, 0, 1, 0, 0, 0, 0, 1}, 0);
  EXPECT_EQ(crate.pose.scale, 2.0);
  EXPECT_EQ(crate.motion.velocityMPerFrame, Vec3(0.001, 0, -0.002));
  EXPECT_EQ(crate.motion.axis, Vec3(0, 0, 1));  // [0, 0, 2] normalised
  EXPECT_EQ(crate.motion.angularDegPerFrame, 1.5);
  EXPECT_EQ(crate.motion.pivot, Vec3(0.15, -0.25, 0.95));
  EXPECT_EQ(crate.albedo.rgb, Vec3(0.2, 0.4, 0.6));
  EXPECT_TRUE(std::holds_alternative<std::monostate>(crate.albedo.texture));

  const Object& ball = scene->objects[2];
  ASSERT_TRUE(std::holds_alternative<Sphere>(ball.shape));
  EXPECT_EQ(std::get<Sphere>(ball.shape).radiusM, 0.07);
  expectMatrix(ball.pose.R, {0, 0, 1, 0, 1, 0, -1, 0, 0}, 0);
  EXPECT_EQ(ball.albedo.rgb, Vec3(0.5, 0.5, 0.5));
  EXPECT_EQ(ball.albedo.specular, 0.4);
  EXPECT_EQ(ball.albedo.shininess, 120.0);

  const Object& can = scene->objects[3];
  EXPECT_EQ(can.name, "object3");  // unnamed: "object" + its index
  ASSERT_TRUE(std::holds_alternative<Cylinder>(can.shape));
  EXPECT_EQ(std::get<Cylinder>(can.shape).radiusM, 0.03);
  EXPECT_EQ(std::get<Cylinder>(can.shape).heightM, 0.25);
  EXPECT_FALSE(std::get<Cylinder>(can.shape).capped);

  const Object& square = scene->objects[4];
  ASSERT_TRUE(std::holds_alternative<Mesh>(square.shape));
  const auto& mesh = std::get<Mesh>(square.shape);
  EXPECT_EQ(mesh.path, (kValidSceneDir / "square.obj").lexically_normal().string());
  EXPECT_EQ(mesh.vertices.size(), 5U);
  EXPECT_EQ(mesh.triangles.size(), 4U);
}

// Given only the required keys, when parsed, then everything else has the documented default.
TEST(SceneJson, DefaultsApplyToEverythingLeftOut) {
  const auto scene =
      parseScene(sceneWithObjects(R"([{"shape": {"type": "plane"}}, {"shape": {"type": "box"}},
                           {"shape": {"type": "sphere"}}, {"shape": {"type": "cylinder"}}])"),
                 "");
  ASSERT_TRUE(scene.has_value()) << scene.error().message();
  EXPECT_EQ(scene->supersampling, 2);
  EXPECT_EQ(scene->lighting.ambient, Vec3(0.03, 0.03, 0.03));
  EXPECT_EQ(scene->lighting.projectorPower, 0.9);
  EXPECT_FALSE(scene->lighting.inverseSquare);
  EXPECT_EQ(scene->lighting.referenceDistanceM, 0.9);
  EXPECT_EQ(scene->lighting.projectorDefocusSigmaPx, 0.0);
  EXPECT_EQ(scene->camera.crosstalk, Mat3::Identity());
  EXPECT_EQ(scene->camera.gain, 1.0);
  EXPECT_EQ(scene->camera.noiseSigma, Vec3(1.8138, 1.2923, 1.6745));
  EXPECT_EQ(scene->camera.defocusSigmaPx, 0.0);
  // The realism settings are off.
  EXPECT_EQ(scene->lighting.projectorBlackLevel, 0.0);
  EXPECT_EQ(scene->lighting.projectorGamma, 1.0);
  EXPECT_EQ(scene->camera.responseGamma, 1.0);
  EXPECT_EQ(scene->camera.vignetting, 0.0);
  EXPECT_EQ(scene->camera.bayer, "none");
  EXPECT_EQ(scene->camera.exposure, 0.0);
  EXPECT_EQ(scene->camera.exposureSamples, 1);

  ASSERT_EQ(scene->objects.size(), 4U);
  for (std::size_t i = 0; i < 4; ++i) {
    const Object& o = scene->objects[i];
    EXPECT_EQ(o.name, "object" + std::to_string(i));
    EXPECT_EQ(o.pose.R, Mat3::Identity());
    EXPECT_EQ(o.pose.t, Vec3::Zero());
    EXPECT_EQ(o.pose.scale, 1.0);
    EXPECT_EQ(o.motion.velocityMPerFrame, Vec3::Zero());
    EXPECT_EQ(o.motion.axis, Vec3(0, 1, 0));
    EXPECT_EQ(o.motion.angularDegPerFrame, 0.0);
    EXPECT_EQ(o.motion.pivot, Vec3::Zero());
    EXPECT_EQ(o.albedo.rgb, Vec3(0.8, 0.8, 0.8));
    EXPECT_TRUE(std::holds_alternative<std::monostate>(o.albedo.texture));
    EXPECT_EQ(o.albedo.specular, 0.0);
    EXPECT_EQ(o.albedo.shininess, 50.0);
  }
  EXPECT_EQ(std::get<Plane>(scene->objects[0].shape).widthM, 1.0);
  EXPECT_EQ(std::get<Plane>(scene->objects[0].shape).heightM, 1.0);
  EXPECT_EQ(std::get<Box>(scene->objects[1].shape).sizeM, Vec3(0.1, 0.1, 0.1));
  EXPECT_EQ(std::get<Sphere>(scene->objects[2].shape).radiusM, 0.1);
  EXPECT_EQ(std::get<Cylinder>(scene->objects[3].shape).radiusM, 0.05);
  EXPECT_EQ(std::get<Cylinder>(scene->objects[3].shape).heightM, 0.1);
  EXPECT_TRUE(std::get<Cylinder>(scene->objects[3].shape).capped);
}

TEST(SceneJson, CheckerWithoutColoursIsTheRgbcmyPanel) {
  const auto scene = parseScene(
      sceneWithObjects(R"([{"shape": {"type": "plane"}, "albedo": {"checker": {}}}])"), "");
  ASSERT_TRUE(scene.has_value()) << scene.error().message();
  const auto& checker = std::get<CheckerTexture>(scene->objects[0].albedo.texture);
  EXPECT_EQ(checker.squareM, 0.04);
  EXPECT_EQ(checker.colours,
            (std::vector<Vec3>{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, 1, 1}, {1, 0, 1}, {1, 1, 0}}));
}

TEST(SceneJson, WholeNumberWrittenWithFractionIsAnInteger) {
  const auto scene =
      parseScene(validSceneWith("\"supersampling\": 3", "\"supersampling\": 4.0"), kValidSceneDir);
  ASSERT_TRUE(scene.has_value()) << scene.error().message();
  EXPECT_EQ(scene->supersampling, 4);
}

Mat3 rotationOf(std::string_view degrees) {
  const auto scene =
      parseScene(sceneWithObjects(R"([{"shape": {"type": "sphere"}, "pose": {"rotation_deg": )" +
                                  std::string(degrees) + "}}]"),
                 "");
  EXPECT_TRUE(scene.has_value()) << scene.error().message();
  return scene.has_value() ? scene->objects[0].pose.R : Mat3::Zero();
}

// Given rotation_deg, when read, then R = Rz(rz) * Ry(ry) * Rx(rx), right-handed, degrees.
TEST(SceneJson, RotationDegMatchesHandComputedMatrices) {
  // Quarter turns are exact: no 6e-17 where a zero belongs.
  expectMatrix(rotationOf("[90, 0, 0]"), {1, 0, 0, 0, 0, -1, 0, 1, 0}, 0);
  expectMatrix(rotationOf("[0, 90, 0]"), {0, 0, 1, 0, 1, 0, -1, 0, 0}, 0);
  expectMatrix(rotationOf("[0, 0, 90]"), {0, -1, 0, 1, 0, 0, 0, 0, 1}, 0);
  expectMatrix(rotationOf("[0, 0, -270]"), {0, -1, 0, 1, 0, 0, 0, 0, 1}, 0);
  expectMatrix(rotationOf("[180, 0, 0]"), {1, 0, 0, 0, -1, 0, 0, 0, -1}, 0);
  // Ry(90) * Rx(90): x is turned first (y -> z), then y (z -> x, x -> -z).
  expectMatrix(rotationOf("[90, 90, 0]"), {0, 1, 0, 0, 0, -1, -1, 0, 0}, 0);

  // rx = 30°, ry = 45°, rz = 60°, from the closed form of Rz * Ry * Rx:
  // [cz cy, cz sy sx - sz cx, cz sy cx + sz sx; sz cy, sz sy sx + cz cx, sz sy cx - cz sx;
  //  -sy, cy sx, cy cx].
  const double r2 = std::sqrt(2.0);
  const double r3 = std::sqrt(3.0);
  const double r6 = std::sqrt(6.0);
  expectMatrix(rotationOf("[30, 45, 60]"),
               {r2 / 4, r2 / 8 - 0.75, r6 / 8 + r3 / 4,      //
                r6 / 4, r6 / 8 + r3 / 4, 3 * r2 / 8 - 0.25,  //
                -r2 / 2, r2 / 4, r6 / 4},
               1e-15);
  expectMatrix(rotationOf("[30, 0, 0]"), {1, 0, 0, 0, r3 / 2, -0.5, 0, 0.5, r3 / 2}, 1e-15);
}

// The order shows in where a vector goes: with rotation_deg [90, 0, 90], local +y is first turned
// to +z by the x rotation and then stays there under the z rotation.
TEST(SceneJson, RotationDegTurnsAboutXFirst) {
  const Vec3 y = rotationOf("[90, 0, 90]") * Vec3::UnitY();
  EXPECT_NEAR((y - Vec3::UnitZ()).norm(), 0, 1e-15) << y.transpose();
}

TEST(SceneJson, MotionAxisIsNormalised) {
  const auto scene = parseScene(
      sceneWithObjects(R"([{"shape": {"type": "box"}, "motion": {"axis": [3, 0, -4]}}])"), "");
  ASSERT_TRUE(scene.has_value()) << scene.error().message();
  EXPECT_NEAR((scene->objects[0].motion.axis - Vec3(0.6, 0, -0.8)).norm(), 0, 1e-15);
}

// Given a scene file in testdata/scenes naming "../meshes/...", when loaded (from any working
// directory), then the meshes are read from testdata/meshes and their paths are the resolved ones.
TEST(SceneJson, RelativePathsResolveAgainstTheSceneFile) {
  const auto scene = loadScene(kTestData / "scenes/relative_paths.json");
  ASSERT_TRUE(scene.has_value()) << scene.error().message();
  ASSERT_EQ(scene->objects.size(), 2U);
  const auto& ply = std::get<Mesh>(scene->objects[0].shape);
  EXPECT_EQ(ply.path, (kTestData / "meshes/square.ply").lexically_normal().string());
  expectMesh(ply, kSquareVertices, {{0, 1, 2}, {0, 2, 3}, {3, 2, 4}});
  const auto& obj = std::get<Mesh>(scene->objects[1].shape);
  EXPECT_EQ(obj.path, (kTestData / "meshes/square.obj").lexically_normal().string());
  EXPECT_EQ(obj.triangles.size(), 4U);
  EXPECT_EQ(scene->objects[1].pose.scale, 0.1);

  // parseScene: the same text resolves against the directory it is given.
  const auto again = parseScene(R"({"format": "stripemux-scene/1", "objects": [
      {"shape": {"type": "mesh", "path": "meshes/square.ply"}}]})",
                                kTestData);
  ASSERT_TRUE(again.has_value()) << again.error().message();
  EXPECT_EQ(std::get<Mesh>(again->objects[0].shape).triangles.size(), 3U);
}

TEST(SceneJson, SameMeshTwiceIsLoadedIntoBothObjects) {
  const auto scene = parseScene(sceneWithObjects(R"([
      {"shape": {"type": "mesh", "path": "square.ply"}},
      {"shape": {"type": "mesh", "path": "./square.ply"}, "pose": {"t": [1, 0, 0]}}])"),
                                kValidSceneDir);
  ASSERT_TRUE(scene.has_value()) << scene.error().message();
  for (const auto& object : scene->objects) {
    expectMesh(std::get<Mesh>(object.shape), kSquareVertices, {{0, 1, 2}, {0, 2, 3}, {3, 2, 4}});
  }
}

// Given a PNG next to the scene, when loaded, then its texels are value / 255, row-major, top row
// first, and the path is resolved.
TEST(SceneJson, ImageTextureIsLoadedAsLinearAlbedo) {
  const fs::path dir = tempDir();
  const std::vector<algo::Rgb8> pixels = {{255, 0, 51}, {0, 255, 102}, {10, 20, 30},
                                          {1, 2, 3},    {128, 64, 32}, {0, 0, 0}};
  const RgbImage image{3, 2, pixels};
  ASSERT_TRUE(writePngRgb8(dir / "chart.png", image.view()).has_value());
  writeFile(dir / "scene.json", sceneWithObjects(R"([{"name": "poster", "shape": {"type": "plane"},
      "albedo": {"texture": {"path": "chart.png", "width_m": 0.3, "height_m": 0.2}}}])"));

  const auto scene = loadScene(dir / "scene.json");
  ASSERT_TRUE(scene.has_value()) << scene.error().message();
  const auto& texture = std::get<ImageTexture>(scene->objects[0].albedo.texture);
  EXPECT_EQ(texture.path, (dir / "chart.png").lexically_normal().string());
  EXPECT_EQ(texture.widthM, 0.3);
  EXPECT_EQ(texture.heightM, 0.2);
  EXPECT_EQ(texture.width, 3);
  EXPECT_EQ(texture.height, 2);
  ASSERT_EQ(texture.texels.size(), 6U);
  EXPECT_EQ(texture.texels[0], (std::array<float, 3>{1.0F, 0.0F, 0.2F}));
  EXPECT_EQ(texture.texels[1], (std::array<float, 3>{0.0F, 1.0F, 0.4F}));
  EXPECT_FLOAT_EQ(texture.texels[4][0], 128.0F / 255.0F);
  EXPECT_FLOAT_EQ(texture.texels[3][2], 3.0F / 255.0F);
  EXPECT_EQ(texture.texels[5], (std::array<float, 3>{0.0F, 0.0F, 0.0F}));
}

TEST(SceneJson, ShippedMeshesLoadFromAScene) {
  const auto scene = parseScene(sceneWithObjects(R"([
      {"name": "bunny", "shape": {"type": "mesh", "path": "bun_zipper_res2.ply"}},
      {"name": "head", "shape": {"type": "mesh", "path": "leeperrysmith_head.ply"},
       "pose": {"scale": 0.03}}])"),
                                kShippedMeshes);
  ASSERT_TRUE(scene.has_value()) << scene.error().message();
  EXPECT_EQ(std::get<Mesh>(scene->objects[0].shape).vertices.size(), 8171U);
  EXPECT_EQ(std::get<Mesh>(scene->objects[1].shape).triangles.size(), 17672U);
}

// ---------------------------------------------------------------------------------------------
// One test per kind of scene error: the field path and the wording of the problem.

TEST(SceneJsonErrors, MalformedJsonNamesLineAndColumn) {
  expectRejected("{\n  \"format\": \"stripemux-scene/1\"\n  \"objects\": []\n}", "",
                 {"not valid JSON", "line 3, column"});
  expectRejected(" \n", "", {"not valid JSON", "the text is empty"});
}

TEST(SceneJsonErrors, TopLevelMustBeAnObject) {
  expectRejected("[1, 2]", "", {"top level must be a JSON object", "got an array of 2 elements"});
}

TEST(SceneJsonErrors, Format) {
  expectRejected(validSceneWith("\"format\": \"stripemux-scene/1\",", ""), "format",
                 {"required field is missing", "\"format\": \"stripemux-scene/1\""});
  expectRejected(validSceneWith("\"stripemux-scene/1\"", "1"), "format",
                 {"must be a string such as \"stripemux-scene/1\", got a number (1)"});
  expectRejected(validSceneWith("\"stripemux-scene/1\"", "\"stripemux-scene/2\""), "format",
                 {"unsupported version \"stripemux-scene/2\"; supported: \"stripemux-scene/1\""});
  expectRejected(validSceneWith("\"stripemux-scene/1\"", "\"stripemux-rig/1\""), "format",
                 {"unknown format \"stripemux-rig/1\" (this is a rig.json, not a scene)"});
}

TEST(SceneJsonErrors, DuplicateKeyNamesItsObject) {
  expectRejected(validSceneWith("\"pose\": {\"t\": [0, 0, 1.1]}",
                                "\"pose\": {\"t\": [0, 0, 1.1], \"t\": [0, 0, 1]}"),
                 "objects[0].pose", {"key \"t\" appears more than once"});
}

TEST(SceneJsonErrors, UnknownKeysAreRejectedWithASuggestion) {
  expectRejected(validSceneWith("\"lighting\":", "\"lightning\":"), "",
                 {"unknown key \"lightning\" (did you mean \"lighting\"?)",
                  "allowed keys: format, supersampling, lighting, camera_response, objects"});
  expectRejected(
      validSceneWith("\"colours\"", "\"colors\""), "objects[0].albedo.checker",
      {"unknown key \"colors\" (did you mean \"colours\"?)", "allowed keys: square_m, colours"});
  expectRejected(validSceneWith("\"gain\"", "\"Gain\""), "camera_response",
                 {"unknown key \"Gain\" (did you mean \"gain\"?)"});
  expectRejected(validSceneWith("\"angular_deg_per_frame\"", "\"angular_deg\""),
                 "objects[1].motion",
                 {"unknown key \"angular_deg\" (did you mean \"angular_deg_per_frame\"?)"});
  expectRejected(
      validSceneWith("\"name\": \"ball\",", "\"name\": \"ball\", \"colour\": 1,"), "objects[2]",
      {"unknown key \"colour\"", "allowed keys: name, shape, pose, motion, pose_sequence, albedo"});
}

// A key that belongs to another shape type says so.
TEST(SceneJsonErrors, ShapeKeysDependOnTheType) {
  expectRejected(validSceneWith("\"radius_m\": 0.07", "\"radius_m\": 0.07, \"height_m\": 1"),
                 "objects[2].shape",
                 {"unknown key \"height_m\" (height_m is for plane and cylinder shapes, not for "
                  "a sphere)",
                  "allowed keys: type, radius_m"});
  expectRejected(validSceneWith("\"width_m\": 1.2", "\"width\": 1.2"), "objects[0].shape",
                 {"unknown key \"width\" (did you mean \"width_m\"?)"});
}

TEST(SceneJsonErrors, ShapeTypeIsRequiredAndKnown) {
  expectRejected(validSceneWith("\"type\": \"box\"", "\"type\": \"cube\""), "objects[1].shape.type",
                 {"unknown shape type \"cube\" (did you mean \"box\"?)",
                  "types: plane, box, sphere, cylinder, mesh"});
  expectRejected(validSceneWith("\"type\": \"sphere\"", "\"type\": \"spehre\""),
                 "objects[2].shape.type", {"(did you mean \"sphere\"?)"});
  expectRejected(validSceneWith("\"type\": \"sphere\", ", ""), "objects[2].shape.type",
                 {"required field is missing; one of plane, box, sphere, cylinder, mesh"});
  expectRejected(validSceneWith("\"type\": \"sphere\"", "\"type\": 3"), "objects[2].shape.type",
                 {"must be a string", "got a number (3)"});
}

TEST(SceneJsonErrors, RequiredFieldsPresent) {
  expectRejected(
      validSceneWith("\"shape\": {\"type\": \"cylinder\", \"radius_m\": 0.03, \"height_m\": 0.25, "
                     "\"capped\": false}",
                     "\"pose\": {}"),
      "objects[3].shape", {"required field is missing"});
  expectRejected(validSceneWith(", \"path\": \"square.obj\"", ""), "objects[4].shape.path",
                 {"required field is missing", "PLY or OBJ"});
  expectRejected(R"({"format": "stripemux-scene/1"})", "objects",
                 {"required field is missing", "at least one object"});
}

TEST(SceneJsonErrors, RightJsonTypes) {
  expectRejected(validSceneWith("\"scale\": 2", "\"scale\": \"2\""), "objects[1].pose.scale",
                 {"must be a number, got a string (\"2\")"});
  expectRejected(validSceneWith("\"inverse_square\": true", "\"inverse_square\": 1"),
                 "lighting.inverse_square", {"must be true or false, got a number (1)"});
  expectRejected(
      R"({"format": "stripemux-scene/1", "lighting": [0.5], "objects": [{"shape": {"type": "box"}}]})",
      "lighting", {"must be an object (the lighting settings), got an array of 1 element"});
  expectRejected(sceneWithObjects(R"({"shape": {"type": "box"}})"), "objects",
                 {"must be an array of objects, got an object"});
  expectRejected(sceneWithObjects(R"(["wall"])"), "objects[0]",
                 {"must be an object (one scene object", "got a string (\"wall\")"});
  expectRejected(validSceneWith("\"pose\": {\"rotation_deg\": [0, 90, 0]}", "\"pose\": 5"),
                 "objects[2].pose", {"must be an object", "got a number (5)"});
  expectRejected(validSceneWith("{\"type\": \"box\", \"size_m\": [0.1, 0.2, 0.3]}", "\"box\""),
                 "objects[1].shape", {"must be an object {\"type\": ...}, got a string"});
  expectRejected(validSceneWith("\"name\": \"wall\"", "\"name\": 7"), "objects[0].name",
                 {"must be a string, got a number (7)"});
}

TEST(SceneJsonErrors, ArrayLengths) {
  expectRejected(validSceneWith("\"t\": [0.1, -0.2, 0.9]", "\"t\": [0.1, -0.2]"),
                 "objects[1].pose.t",
                 {"must be an array of 3 numbers (x, y, z in metres), got an array of 2 elements"});
  expectRejected(validSceneWith("0.07, 0.8]", "0.07]"), "camera_response.crosstalk",
                 {"must be an array of 9 numbers (row-major 3x3 matrix", "got an array of 8"});
  expectRejected(validSceneWith("[0, 0.5, 1]]", "[0, 0.5]]"),
                 "objects[0].albedo.checker.colours[1]",
                 {"must be an array of 3 numbers (r, g, b, each 0 to 1)"});
  expectRejected(validSceneWith("\"colours\": [[1, 0, 0], [0, 0.5, 1]]", "\"colours\": []"),
                 "objects[0].albedo.checker.colours",
                 {"must be an array of at least one [r, g, b] colour, got an array of 0 elements"});
}

TEST(SceneJsonErrors, NumbersMustBeFinite) {
  expectRejected(validSceneWith("\"t\": [0, 0, 1.1]", "\"t\": [0, 0, 1e999]"),
                 "objects[0].pose.t[2]",
                 {"must be a finite number; 1e999 is too large for a double"});
}

TEST(SceneJsonErrors, SizesMustBePositive) {
  expectRejected(validSceneWith("\"radius_m\": 0.07", "\"radius_m\": 0"),
                 "objects[2].shape.radius_m", {"must be positive, got 0"});
  expectRejected(validSceneWith("\"size_m\": [0.1, 0.2, 0.3]", "\"size_m\": [0.1, -0.2, 0.3]"),
                 "objects[1].shape.size_m[1]", {"must be positive, got -0.2"});
  expectRejected(validSceneWith("\"scale\": 2", "\"scale\": -2"), "objects[1].pose.scale",
                 {"must be positive, got -2"});
  expectRejected(validSceneWith("\"square_m\": 0.05", "\"square_m\": 0"),
                 "objects[0].albedo.checker.square_m", {"must be positive, got 0"});
  expectRejected(validSceneWith("\"gain\": 1.5", "\"gain\": 0"), "camera_response.gain",
                 {"must be positive, got 0"});
  expectRejected(validSceneWith("\"reference_distance_m\": 1.25", "\"reference_distance_m\": 0"),
                 "lighting.reference_distance_m", {"must be positive, got 0"});
}

TEST(SceneJsonErrors, SupersamplingIsAnIntegerFrom1To8) {
  for (const auto* bad : {"0", "9", "2.5", "-1"}) {
    expectRejected(
        validSceneWith("\"supersampling\": 3", std::string("\"supersampling\": ") + bad),
        "supersampling",
        {"must be an integer from 1 to 8 (samples per pixel side), got " + std::string(bad)});
  }
}

TEST(SceneJsonErrors, SigmasMustNotBeNegative) {
  expectRejected(validSceneWith("\"noise_sigma\": [2, 1.5, 0.25]", "\"noise_sigma\": [2, -1.5, 0]"),
                 "camera_response.noise_sigma[1]", {"must not be negative, got -1.5"});
  expectRejected(validSceneWith("\"defocus_sigma_px\": 0.75", "\"defocus_sigma_px\": -0.5"),
                 "camera_response.defocus_sigma_px", {"must not be negative, got -0.5"});
  expectRejected(
      validSceneWith("\"projector_defocus_sigma_px\": 0.5", "\"projector_defocus_sigma_px\": -1"),
      "lighting.projector_defocus_sigma_px", {"must not be negative, got -1"});
}

TEST(SceneJsonErrors, ColoursAreFractions) {
  expectRejected(
      validSceneWith("\"ambient\": [0.01, 0.02, 0.04]", "\"ambient\": [0.01, 0.02, -0.5]"),
      "lighting.ambient[2]", {"must not be negative, got -0.5"});
  expectRejected(validSceneWith("\"rgb\": [0.2, 0.4, 0.6]", "\"rgb\": [-0.1, 0.4, 0.6]"),
                 "objects[1].albedo.rgb[0]", {"must be between 0 and 1, got -0.1"});
  expectRejected(validSceneWith("[0, 0.5, 1]]", "[0, 0.5, 2]]"),
                 "objects[0].albedo.checker.colours[1][2]", {"must be between 0 and 1, got 2"});
}

// Given each realism setting just outside its physical range (docs/scene-format.md), when parsed,
// then the scene is refused with the key and the range named.
TEST(SceneJsonErrors, RealismSettingsStayInTheirPhysicalRanges) {
  struct Case {
    std::string_view from;
    std::string_view to;
    std::string_view field;
    std::string_view problem;
  };
  const std::array<Case, 14> cases = {{
      {"\"projector_black_level\": 0.01", "\"projector_black_level\": 0.25",
       "lighting.projector_black_level", "must be from 0 to 0.2, got 0.25"},
      {"\"projector_black_level\": 0.01", "\"projector_black_level\": -0.01",
       "lighting.projector_black_level", "must be from 0 to 0.2, got -0.01"},
      {"\"projector_gamma\": 2.2", "\"projector_gamma\": 0.9", "lighting.projector_gamma",
       "must be from 1 to 3, got 0.9"},
      {"\"response_gamma\": 1.8", "\"response_gamma\": 3.5", "camera_response.response_gamma",
       "must be from 1 to 3, got 3.5"},
      {"\"vignetting\": 0.3", "\"vignetting\": 0.9", "camera_response.vignetting",
       "must be from 0 to 0.8, got 0.9"},
      {"\"bayer\": \"grbg\"", "\"bayer\": \"rggbb\"", "camera_response.bayer",
       R"(unknown pattern "rggbb" (did you mean "rggb"?); patterns: "none", "rggb", "bggr", )"},
      {"\"bayer\": \"grbg\"", "\"bayer\": 1", "camera_response.bayer",
       "must be a string, one of \"none\""},
      {"\"exposure\": 0.5", "\"exposure\": 1.5", "camera_response.exposure",
       "must be from 0 to 1, got 1.5"},
      {"\"exposure_samples\": 5", "\"exposure_samples\": 0", "camera_response.exposure_samples",
       "must be an integer from 1 to 16 (time samples over the exposure), got 0"},
      {"\"exposure_samples\": 5", "\"exposure_samples\": 17", "camera_response.exposure_samples",
       "got 17"},
      {"\"exposure_samples\": 5", "\"exposure_samples\": 2.5", "camera_response.exposure_samples",
       "got 2.5"},
      {"\"specular\": 0.4", "\"specular\": 1.5", "objects[2].albedo.specular",
       "must be between 0 and 1, got 1.5"},
      {"\"shininess\": 120", "\"shininess\": 0.5", "objects[2].albedo.shininess",
       "must be from 1 to 10000, got 0.5"},
      {"\"shininess\": 120", "\"shininess\": 1e5", "objects[2].albedo.shininess",
       "must be from 1 to 10000, got 100000"},
  }};
  for (const auto& c : cases) {
    expectRejected(validSceneWith(c.from, c.to), c.field, {c.problem});
  }
}

// Given a scene built in memory with an unknown mosaic, when validated, then it is refused as
// the file would be.
TEST(SceneJsonErrors, ValidateSceneRefusesAnUnknownBayerPattern) {
  Scene scene;
  scene.objects.emplace_back();
  scene.camera.bayer = "RGGB";
  const auto valid = config::validateScene(scene);
  ASSERT_FALSE(valid.has_value());
  EXPECT_EQ(valid.error().field, "camera_response.bayer");
  EXPECT_TRUE(contains(valid.error().problem, "unknown pattern \"RGGB\"")) << valid.error().problem;
}

TEST(SceneJsonErrors, RMustBeARotation) {
  expectRejected(validSceneWith("\"R\": [0, -1, 0, 1, 0, 0, 0, 0, 1]",
                                "\"R\": [0, -1.01, 0, 1, 0, 0, 0, 0, 1]"),
                 "objects[1].pose.R",
                 {"not a rotation: max |R*R^T - I| is 0.0201 (must be at most 1e-06)"});
  expectRejected(
      validSceneWith("\"R\": [0, -1, 0, 1, 0, 0, 0, 0, 1]", "\"R\": [0, 1, 0, 1, 0, 0, 0, 0, 1]"),
      "objects[1].pose.R", {"det R is -1", "det -1 is a reflection"});
  // 4e-7 is within the tolerance of 1e-6.
  EXPECT_TRUE(parseScene(validSceneWith("\"R\": [0, -1, 0, 1, 0, 0, 0, 0, 1]",
                                        "\"R\": [0, -1.0000002, 0, 1, 0, 0, 0, 0, 1]"),
                         kValidSceneDir)
                  .has_value());
}

TEST(SceneJsonErrors, RAndRotationDegExcludeEachOther) {
  expectRejected(validSceneWith("\"rotation_deg\": [0, 90, 0]",
                                "\"rotation_deg\": [0, 90, 0], \"R\": [1, 0, 0, 0, 1, 0, 0, 0, 1]"),
                 "objects[2].pose",
                 {"give the rotation as \"R\" or as \"rotation_deg\", not both"});
}

TEST(SceneJsonErrors, MotionAxisMustNotBeZero) {
  expectRejected(validSceneWith("\"axis\": [0, 0, 2]", "\"axis\": [0, 0, 0]"),
                 "objects[1].motion.axis",
                 {"must not be the zero vector; it is the direction of the rotation axis"});
}

TEST(SceneJsonErrors, AlbedoIsExactlyOneKind) {
  expectRejected(validSceneWith("\"albedo\": {\"rgb\": [0.2, 0.4, 0.6]}", "\"albedo\": {}"),
                 "objects[1].albedo", {"needs exactly one of \"rgb\", \"checker\" or \"texture\""});
  expectRejected(
      validSceneWith("\"rgb\": [0.2, 0.4, 0.6]", "\"rgb\": [0.2, 0.4, 0.6], \"checker\": {}"),
      "objects[1].albedo",
      {"needs exactly one of \"rgb\", \"checker\" or \"texture\", got \"rgb\" and "
       "\"checker\""});
}

TEST(SceneJsonErrors, ObjectNamesAreUniqueAndNonEmpty) {
  expectRejected(validSceneWith("\"name\": \"ball\"", "\"name\": \"wall\""), "objects[2].name",
                 {"\"wall\" is already the name of objects[0]; object names must be unique"});
  expectRejected(validSceneWith("\"name\": \"ball\"", "\"name\": \"object3\""), "objects[3]",
                 {"has no name, and its default name \"object3\" is already the name of "
                  "objects[2]"});
  expectRejected(
      sceneWithObjects(
          R"([{"shape": {"type": "box"}}, {"name": "object0", "shape": {"type": "box"}}])"),
      "objects[1].name",
      {"\"object0\" is already the name of the unnamed objects[0] (its default)"});
  expectRejected(validSceneWith("\"name\": \"ball\"", "\"name\": \"\""), "objects[2].name",
                 {"must not be empty"});
}

TEST(SceneJsonErrors, AtLeastOneObject) {
  expectRejected(sceneWithObjects("[]"), "objects", {"at least one object is required, got none"});
}

// Given a mesh path that does not exist, then the error names the field and the resolved path.
TEST(SceneJsonErrors, MissingMeshNamesTheResolvedPath) {
  const fs::path file = kTestData / "scenes/missing_mesh.json";
  const auto scene = loadScene(file);
  ASSERT_FALSE(scene.has_value());
  EXPECT_EQ(scene.error().file, file.string());
  EXPECT_EQ(scene.error().field, "objects[1].shape.path");
  const std::string resolved = (kTestData / "meshes/no_such_mesh.ply").string();
  EXPECT_EQ(scene.error().problem,
            "cannot load mesh " + resolved + ": cannot read the file: No such file or directory");
  EXPECT_EQ(scene.error().message(),
            file.string() + ": objects[1].shape.path: " + scene.error().problem);
}

TEST(SceneJsonErrors, BadMeshNamesTheMeshFileAndLine) {
  const auto scene = loadScene(kTestData / "scenes/bad_mesh.json");
  ASSERT_FALSE(scene.has_value());
  EXPECT_EQ(scene.error().field, "objects[1].shape.path");
  EXPECT_EQ(scene.error().problem,
            "cannot load mesh " + (kTestData / "meshes/bad_index.ply").string() +
                ": line 15: face 1 refers to vertex 3, but the file has 3 vertices (0 to 2)");
}

TEST(SceneJsonErrors, MissingTextureNamesTheResolvedPath) {
  expectRejected(
      sceneWithObjects(
          R"([{"shape": {"type": "plane"}, "albedo": {"texture": {"path": "nope.png"}}}])"),
      "objects[0].albedo.texture.path",
      {"cannot load texture " + (kValidSceneDir / "nope.png").string() +
       ": cannot read the file: No such file or directory"});
  // A file that is not a PNG: libpng's reason, after the path.
  expectRejected(
      sceneWithObjects(
          R"([{"shape": {"type": "plane"}, "albedo": {"texture": {"path": "square.obj"}}}])"),
      "objects[0].albedo.texture.path",
      {"cannot load texture " + (kValidSceneDir / "square.obj").string() + ": "});
}

TEST(SceneJsonErrors, LoadSceneNamesAnUnreadableFile) {
  const auto scene = loadScene(kTestData / "scenes/no_such_scene.json");
  ASSERT_FALSE(scene.has_value());
  EXPECT_EQ(scene.error().message(), (kTestData / "scenes/no_such_scene.json").string() +
                                         ": cannot read the file: No such file or directory");
  const auto directory = loadScene(kTestData / "scenes");
  ASSERT_FALSE(directory.has_value());
  EXPECT_TRUE(contains(directory.error().problem, "it is a directory"));
}

TEST(SceneJsonErrors, SizeAndNestingAreBounded) {
  expectRejected(std::string(200, '[') + std::string(200, ']'), "",
                 {"nested 200 levels deep; a scene.json needs 7 and at most 16 are accepted"});
  std::string big = sceneWithObjects("[{\"shape\": {\"type\": \"box\"}}]");
  big.insert(1, std::string(std::size_t{1} << 20U, ' '));
  expectRejected(big, "", {"bytes; a scene.json is at most 1048576 bytes"});
}

// ---------------------------------------------------------------------------------------------
// Mesh files

TEST(MeshPly, AsciiFixtureSkipsWhatItDoesNotNeed) {
  const auto mesh = loadMesh(kTestData / "meshes/square.ply");
  ASSERT_TRUE(mesh.has_value()) << mesh.error().message();
  EXPECT_EQ(mesh->path, (kTestData / "meshes/square.ply").string());
  expectMesh(*mesh, kSquareVertices, {{0, 1, 2}, {0, 2, 3}, {3, 2, 4}});
}

TEST(MeshPly, BinaryBigEndianWithMixedTypes) {
  const auto mesh = parseMesh(bigEndianFixture(), MeshFormat::kPly);
  ASSERT_TRUE(mesh.has_value()) << mesh.error().message();
  expectMesh(*mesh, {{0.5F, -1.25F, 3}, {2, 0, -4}, {-0.125F, 8.5F, 0}, {0.75F, 1.5F, 300}},
             {{0, 1, 2}, {1, 3, 2}, {1, 2, 0}});
}

TEST(MeshPly, BinaryLittleEndianWithIntegerCoordinates) {
  const auto mesh = parseMesh(littleEndianFixture(), MeshFormat::kPly);
  ASSERT_TRUE(mesh.has_value()) << mesh.error().message();
  expectMesh(*mesh, {{-5, 60000, -70000}, {127, 0, 1}, {-128, 1, 123456}}, {{2, 0, 1}});
}

TEST(MeshPly, ExtensionIsCaseInsensitive) {
  const fs::path dir = tempDir();
  writeFile(dir / "BIG.PLY", bigEndianFixture());
  const auto mesh = loadMesh(dir / "BIG.PLY");
  ASSERT_TRUE(mesh.has_value()) << mesh.error().message();
  EXPECT_EQ(mesh->path, (dir / "BIG.PLY").string());
  EXPECT_EQ(mesh->triangles.size(), 3U);
}

// The shipped meshes, with the counts of hal/sim/scenes/meshes/PROVENANCE.md and values read
// off the files (first and last vertex lines, first and last face).
TEST(MeshPly, ShippedBunnyLoads) {
  const auto start = std::chrono::steady_clock::now();
  const auto mesh = loadMesh(kShippedMeshes / "bun_zipper.ply");
  const auto elapsed = std::chrono::steady_clock::now() - start;
  ASSERT_TRUE(mesh.has_value()) << mesh.error().message();
  EXPECT_EQ(mesh->vertices.size(), 35947U);
  EXPECT_EQ(mesh->triangles.size(), 69451U);
  expectMesh(Mesh{{}, {mesh->vertices.front(), mesh->vertices.back()}, {}},
             {{-0.0378297F, 0.12794F, 0.00447467F}, {-0.0400442F, 0.15362F, -0.00816685F}}, {});
  EXPECT_EQ(mesh->triangles.front(), (Triangle{21216, 21215, 20399}));
  EXPECT_EQ(mesh->triangles.back(), (Triangle{17277, 17346, 17345}));
  RecordProperty("bun_zipper_load_ms",
                 std::to_string(std::chrono::duration<double, std::milli>(elapsed).count()));
}

TEST(MeshPly, ShippedDecimatedBunnyAndHeadLoad) {
  const auto bunny = loadMesh(kShippedMeshes / "bun_zipper_res2.ply");
  ASSERT_TRUE(bunny.has_value()) << bunny.error().message();
  EXPECT_EQ(bunny->vertices.size(), 8171U);
  EXPECT_EQ(bunny->triangles.size(), 16301U);

  const auto head = loadMesh(kShippedMeshes / "leeperrysmith_head.ply");  // binary LE
  ASSERT_TRUE(head.has_value()) << head.error().message();
  EXPECT_EQ(head->vertices.size(), 8838U);
  EXPECT_EQ(head->triangles.size(), 17672U);
  EXPECT_EQ(head->vertices.front(), Eigen::Vector3f(0.92991102F, -0.52187699F, -0.70019197F));
  EXPECT_EQ(head->triangles.front(), (Triangle{0, 1, 3}));
  EXPECT_EQ(head->triangles.back(), (Triangle{8837, 8835, 8831}));
}

TEST(MeshObj, FixtureWithAllFaceFormsAndNegativeIndices) {
  const auto mesh = loadMesh(kTestData / "meshes/square.obj");
  ASSERT_TRUE(mesh.has_value()) << mesh.error().message();
  expectMesh(*mesh, kSquareVertices, {{0, 1, 2}, {0, 2, 3}, {3, 2, 4}, {0, 2, 3}});
}

TEST(MeshObj, ForwardReferencesAndCrlf) {
  const auto mesh = parseMesh("f 1 2 3\r\nv 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\n", MeshFormat::kObj);
  ASSERT_TRUE(mesh.has_value()) << mesh.error().message();
  expectMesh(*mesh, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}});
}

// ---------------------------------------------------------------------------------------------
// One test per kind of mesh error: the file, the line (text) or byte (binary), the wording.

constexpr std::string_view kPlyHead =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
    "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";

TEST(MeshErrors, MissingFileAndUnknownExtension) {
  const auto missing = loadMesh("/nonexistent/mesh.ply");
  ASSERT_FALSE(missing.has_value());
  EXPECT_EQ(missing.error().message(),
            "/nonexistent/mesh.ply: cannot read the file: No such file or directory");
  const auto stl = loadMesh(kTestData / "meshes/square.stl");
  ASSERT_FALSE(stl.has_value());
  EXPECT_EQ(stl.error().problem,
            "unknown mesh file extension \".stl\"; meshes are PLY (.ply) or Wavefront OBJ (.obj)");
  EXPECT_EQ(stl.error().file, (kTestData / "meshes/square.stl").string());
}

TEST(MeshErrors, NotAPlyFile) {
  expectMeshRejected("", MeshFormat::kPly, {"not a PLY file: the file is empty"});
  expectMeshRejected(
      "solid cube\n", MeshFormat::kPly,
      {"line 1: not a PLY file: the first line must be \"ply\", got \"solid cube\""});
}

TEST(MeshErrors, UnsupportedPlyFormat) {
  expectMeshRejected("ply\nformat binary_middle_endian 1.0\n", MeshFormat::kPly,
                     {"line 2: unsupported PLY format \"format binary_middle_endian 1.0\"",
                      "supported: ascii 1.0, binary_little_endian 1.0, binary_big_endian 1.0"});
  expectMeshRejected("ply\nelement vertex 3\n", MeshFormat::kPly,
                     {"line 2: expected the format line"});
}

TEST(MeshErrors, BadHeaderLines) {
  expectMeshRejected("ply\nformat ascii 1.0\nelement vertex 3\nproperty float16 x\n",
                     MeshFormat::kPly,
                     {"line 4: unknown property type \"float16\"", "PLY types: char, uchar"});
  expectMeshRejected("ply\nformat ascii 1.0\nelement vertex -3\n", MeshFormat::kPly,
                     {"line 3: the count of element \"vertex\", \"-3\", is not a non-negative "
                      "integer"});
  expectMeshRejected("ply\nformat ascii 1.0\nproperty float x\n", MeshFormat::kPly,
                     {"line 3: a property before any element"});
  expectMeshRejected("ply\nformat ascii 1.0\nelement vertex 1\nproperty list uchar x\n",
                     MeshFormat::kPly, {"line 4: expected \"property <type> <name>\""});
  expectMeshRejected("ply\nformat ascii 1.0\nelemnt vertex 1\n", MeshFormat::kPly,
                     {"line 3: unknown header keyword \"elemnt\""});
  expectMeshRejected("ply\nformat ascii 1.0\nelement vertex 1\n", MeshFormat::kPly,
                     {"the header has no end_header line (the file ends at line 3)"});
}

TEST(MeshErrors, HeaderLacksWhatAMeshNeeds) {
  expectMeshRejected(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
      "property float y\nend_header\n0 0\n",
      MeshFormat::kPly, {"element \"vertex\" (line 3) has no property \"z\""});
  expectMeshRejected(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n0 0 0\n",
      MeshFormat::kPly,
      {"the header declares no \"face\" element: a point cloud has no triangles"});
  expectMeshRejected("ply\nformat ascii 1.0\nelement face 0\nend_header\n", MeshFormat::kPly,
                     {"the header declares no \"vertex\" element"});
  expectMeshRejected(
      "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\n"
      "property float y\nproperty float z\nelement face 0\nproperty int "
      "vertex_indices\nend_header\n",
      MeshFormat::kPly,
      {"element \"face\" (line 7) has no list property \"vertex_indices\" or "
       "\"vertex_index\""});
}

TEST(MeshErrors, AsciiRowsMustMatchTheHeader) {
  expectMeshRejected(std::string(kPlyHead) + "0 0 0\n1 0\n0 1 0\n3 0 1 2\n", MeshFormat::kPly,
                     {"line 11: vertex 1: the line ends before property \"z\""});
  expectMeshRejected(std::string(kPlyHead) + "0 0 0\n1 0 0 1\n0 1 0\n3 0 1 2\n", MeshFormat::kPly,
                     {"line 11: vertex 1: more values than element \"vertex\" declares (\"1\" "
                      "after the last property, \"z\")"});
  expectMeshRejected(std::string(kPlyHead) + "0 0 0\n1 0,5 0\n0 1 0\n3 0 1 2\n", MeshFormat::kPly,
                     {"line 11: vertex 1: property \"y\": \"0,5\" is not a number"});
}

TEST(MeshErrors, AsciiFileEndsEarlyOrRunsOn) {
  expectMeshRejected(std::string(kPlyHead) + "0 0 0\n1 0 0\n0 1 0\n", MeshFormat::kPly,
                     {"line 12: the file ends before face 0 of the 1 the header declares"});
  expectMeshRejected(std::string(kPlyHead) + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 2 1 0\n",
                     MeshFormat::kPly,
                     {"line 14: unexpected data after the last element: \"3 2 1 0\""});
}

TEST(MeshErrors, BinaryTruncatedOrTooLong) {
  const std::string full = bigEndianFixture();
  expectMeshRejected(
      std::string_view(full).substr(0, full.size() - 10), MeshFormat::kPly,
      {"face 1 (byte ", "): the file ends before property \"vertex_indices\"", "truncated"});
  expectMeshRejected(full + "xy", MeshFormat::kPly,
                     {"2 bytes of unexpected data after the last element"});
}

TEST(MeshErrors, FaceIndicesInRange) {
  expectMeshRejected(std::string(kPlyHead) + "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", MeshFormat::kPly,
                     {"line 13: face 0 refers to vertex 3, but the file has 3 vertices (0 to 2)"});
  std::string noVertices(kPlyHead);
  noVertices.replace(noVertices.find("vertex 3"), 8, "vertex 0");
  expectMeshRejected(noVertices + "3 0 1 2\n", MeshFormat::kPly,
                     {"line 10: face 0 refers to vertex 0, but the file has no vertices"});
  expectMeshRejected(std::string(kPlyHead) + "0 0 0\n1 0 0\n0 1 0\n1e30 0 1 2\n", MeshFormat::kPly,
                     {"line 13: face 0: the length of list \"vertex_indices\" is 1e+30, not a "
                      "non-negative 32-bit integer"});
  expectMeshRejected(littleEndianFixture(-1), MeshFormat::kPly,
                     {"face 0 (byte ", "): vertex index -1 is not a non-negative integer"});
  expectMeshRejected(littleEndianFixture(3), MeshFormat::kPly,
                     {"face 0 (byte ", ") refers to vertex 3, but the file has 3 vertices"});
}

TEST(MeshErrors, FacesNeedThreeVerticesAndMeshesATriangle) {
  expectMeshRejected(std::string(kPlyHead) + "0 0 0\n1 0 0\n0 1 0\n2 0 1\n", MeshFormat::kPly,
                     {"line 13: face 0 has 2 vertices; a face needs at least 3"});
  std::string noFaces(kPlyHead);
  noFaces.replace(noFaces.find("face 1"), 6, "face 0");
  expectMeshRejected(noFaces + "0 0 0\n1 0 0\n0 1 0\n", MeshFormat::kPly,
                     {"no triangles: the \"face\" element is empty"});
}

TEST(MeshErrors, CoordinatesMustFitAFloat) {
  expectMeshRejected(std::string(kPlyHead) + "0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n", MeshFormat::kPly,
                     {"line 11: vertex 1: y is not a finite number (nan)"});
  expectMeshRejected("v 0 0 1e39\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", MeshFormat::kObj,
                     {"line 1: vertex: z = 1e+39 is too large for a float"});
}

TEST(MeshErrors, ObjStatements) {
  expectMeshRejected("v 0 0 0\nv 1 0 zero\n", MeshFormat::kObj,
                     {"line 2: vertex: \"zero\" is not a number"});
  expectMeshRejected("v 0 0\n", MeshFormat::kObj,
                     {"line 1: a vertex needs 3 coordinates (v x y z), got 2"});
  expectMeshRejected("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", MeshFormat::kObj,
                     {"line 4: a face needs at least 3 vertices, got 2"});
  expectMeshRejected("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3/x\n", MeshFormat::kObj,
                     {"line 4: face: \"3/x\" is not a vertex reference (i, i/t, i//n or i/t/n)"});
  expectMeshRejected("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", MeshFormat::kObj,
                     {"line 4: face: vertex index 0 is invalid (OBJ indices start at 1"});
}

TEST(MeshErrors, ObjIndicesInRange) {
  expectMeshRejected("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n", MeshFormat::kObj,
                     {"line 4: face: vertex index -4 reaches back past the first vertex (3 "
                      "defined so far)"});
  expectMeshRejected("v 0 0 0\nv 1 0 0\nf 1 2 7\nv 0 1 0\nf 1 2 3\n", MeshFormat::kObj,
                     {"line 3: face refers to vertex 7, but the file has 3 vertices"});
  expectMeshRejected("v 0 0 0\nv 1 0 0\nv 0 1 0\n# no faces\n", MeshFormat::kObj,
                     {"no triangles: the file has no faces (\"f\" lines)"});
}

// ---- validateScene(): the value rules for scenes built in memory ----

// Given every shipped scene, when read, then validateScene() accepts what parseScene() returned:
// reading applies the same rules and leaves nothing (an unnormalised axis, a default) they refuse.
TEST(SceneValidation, EveryShippedSceneStaysValidAfterReading) {
  int scenes = 0;
  for (const auto& entry : fs::directory_iterator(kSourceDir / "hal/sim/scenes")) {
    if (entry.path().extension() != ".json") {
      continue;
    }
    const auto scene = loadScene(entry.path());
    ASSERT_TRUE(scene.has_value()) << scene.error().message();
    const auto valid = config::validateScene(*scene);
    EXPECT_TRUE(valid.has_value()) << entry.path() << ": " << valid.error().message();
    ++scenes;
  }
  EXPECT_GE(scenes, 5);
}

// Given an in-memory scene with one bad value, when validated, then the error names the field as
// the JSON would and says what parseScene() says of the same value.
TEST(SceneValidation, InMemoryErrorsNameTheJsonField) {
  const auto withObject = [](Object o) {
    Scene s;
    s.objects.push_back(std::move(o));
    return s;
  };
  Object ball;
  ball.shape = Sphere{0.0};
  auto e = config::validateScene(withObject(ball));
  ASSERT_FALSE(e.has_value());
  EXPECT_EQ(e.error().field, "objects[0].shape.radius_m");
  EXPECT_EQ(e.error().problem, "must be positive, got 0");
  EXPECT_TRUE(e.error().file.empty());

  Object checker;
  checker.albedo.texture = CheckerTexture{0.04, {{1, 0, 0}, {0, 2, 0}}};
  e = config::validateScene(withObject(checker));
  ASSERT_FALSE(e.has_value());
  EXPECT_EQ(e.error().field, "objects[0].albedo.checker.colours[1][1]");
  EXPECT_EQ(e.error().problem, "must be between 0 and 1, got 2");

  Object turning;
  turning.motion.axis = Vec3::Zero();
  Scene scene = withObject(turning);
  scene.lighting.ambient = {0.1, -0.5, 0.1};  // first in file order
  e = config::validateScene(scene);
  ASSERT_FALSE(e.has_value());
  EXPECT_EQ(e.error().field, "lighting.ambient[1]");
  scene.lighting.ambient = Vec3::Zero();
  e = config::validateScene(scene);
  ASSERT_FALSE(e.has_value());
  EXPECT_EQ(e.error().field, "objects[0].motion.axis");

  Object mesh;
  mesh.shape = Mesh{"meshes/cube.ply", {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 3}}};
  e = config::validateScene(withObject(mesh));
  ASSERT_FALSE(e.has_value());
  EXPECT_EQ(e.error().field, "objects[0].shape.path");
  EXPECT_EQ(e.error().problem, R"(mesh "meshes/cube.ply": triangle 0 names vertex 3 of 3)");
}

}  // namespace
}  // namespace smx::sim

namespace smx::sim {
namespace {

std::string turntableScene(std::string_view table, std::string_view onTable) {
  return R"({"format": "stripemux-scene/1", )" + std::string(table) +
         R"("objects": [{"shape": {"type": "sphere"}, "on_turntable": )" + std::string(onTable) +
         "}]}";
}

TEST(SceneJson, TurntableAxisIsNormalisedAndItsObjectsNeedIt) {
  const auto scene = config::parseScene(
      turntableScene(R"("turntable": {"axis": [0, -3, 0], "pivot": [0, 0, 0.9]}, )", "true"), ".");
  ASSERT_TRUE(scene.has_value()) << scene.error().message();
  ASSERT_TRUE(scene->turntable.has_value());
  EXPECT_EQ(scene->turntable->axis, Vec3(0, -1, 0));
  EXPECT_EQ(scene->turntable->pivot, Vec3(0, 0, 0.9));
  EXPECT_TRUE(scene->objects[0].onTurntable);

  const auto still = config::parseScene(turntableScene("", "false"), ".");
  ASSERT_TRUE(still.has_value());
  EXPECT_FALSE(still->turntable.has_value());

  const auto orphan = config::parseScene(turntableScene("", "true"), ".");
  ASSERT_FALSE(orphan.has_value());
  EXPECT_EQ(orphan.error().field, "objects[0].on_turntable");
  const auto zero =
      config::parseScene(turntableScene(R"("turntable": {"axis": [0, 0, 0]}, )", "true"), ".");
  ASSERT_FALSE(zero.has_value());
  EXPECT_EQ(zero.error().field, "turntable.axis");
  const auto unknown = config::parseScene(
      turntableScene(R"("turntable": {"axis": [0, 1, 0], "centre": [0, 0, 1]}, )", "true"), ".");
  ASSERT_FALSE(unknown.has_value());
  EXPECT_EQ(unknown.error().field, "turntable");
  const auto notBool = config::parseScene(turntableScene("", "1"), ".");
  ASSERT_FALSE(notBool.has_value());
  EXPECT_EQ(notBool.error().field, "objects[0].on_turntable");

  // A scene built in memory is held to the same rule.
  Scene inMemory = *scene;
  inMemory.turntable.reset();
  const auto refused = config::validateScene(inMemory);
  ASSERT_FALSE(refused.has_value());
  EXPECT_EQ(refused.error().field, "objects[0].on_turntable");
}

}  // namespace
}  // namespace smx::sim
