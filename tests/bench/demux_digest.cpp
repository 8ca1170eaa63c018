// Digests of everything orientation demultiplexing outputs, on rendered scenes: a speed change
// that should leave the results alone is checked bit-identical by comparing this program's
// output before and after it (run by hand; not a test, it asserts nothing itself).
//   build/host/tests/bench/demux_digest > before.txt   (… change, rebuild …)
//   build/host/tests/bench/demux_digest | diff before.txt -
// Per rig (rig_2proj_1cam, rig_3proj_1cam) and scene (plane, sphere, rgbcmy_panel, statue,
// bunny; seed 1, camera 0), per projector: FNV-1a 64 of its boundaries, direction plane and tile
// directions and of its three separated planes after run().
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <span>
#include <string>

#include "demux_frame.hpp"
#include "smx/algo/demux.hpp"
#include "smx/eval/sim_frame.hpp"

namespace {

namespace algo = smx::algo;

class Fnv64 {
 public:
  void add(std::span<const std::byte> bytes) {
    for (const std::byte b : bytes) {
      hash_ = (hash_ ^ static_cast<std::uint64_t>(b)) * 0x100000001b3ULL;
    }
  }
  template <class T>
  void addPlane(algo::ImageView<T> plane) {
    for (int y = 0; y < plane.height(); ++y) {
      add(std::as_bytes(std::span(plane.rowPtr(y), static_cast<std::size_t>(plane.width()))));
    }
  }
  [[nodiscard]] std::uint64_t value() const { return hash_; }

 private:
  std::uint64_t hash_ = 0xcbf29ce484222325ULL;
};

template <class T>
std::uint64_t digestOf(algo::ImageView<T> plane) {
  Fnv64 h;
  h.addPlane(plane);
  return h.value();
}

void digestFrame(const std::string& rig, const std::string& scene) {
  const smx::eval::SimFrame frame = smx::eval::renderSimFrame({rig, scene});
  auto demuxed = smx::test::demultiplex(frame);
  algo::Demultiplexer& demux = *demuxed->demux;
  for (int p = 0; p < demux.layout().projectors; ++p) {
    Fnv64 tiles;
    for (const algo::TileDirection& t : demux.tileDirections(p)) {
      const std::uint16_t angle = t.angle;
      tiles.add(std::as_bytes(std::span(&angle, 1)));
      tiles.add(std::as_bytes(std::span(&t.present, 1)));
    }
    const std::uint64_t boundaries = digestOf(demux.boundaries(p));
    const std::uint64_t directions = digestOf(demux.directions(p));
    Fnv64 separated;
    for (int c = 0; c < 3; ++c) {
      separated.addPlane(demux.separated(p, c));
    }
    std::printf(
        "%s %s proj%d boundaries %016llx directions %016llx tiles %016llx "
        "separated %016llx\n",
        rig.c_str(), scene.c_str(), p, static_cast<unsigned long long>(boundaries),
        static_cast<unsigned long long>(directions), static_cast<unsigned long long>(tiles.value()),
        static_cast<unsigned long long>(separated.value()));
  }
}

}  // namespace

int main() {
  try {
    for (const char* rig : {"rig_2proj_1cam.json", "rig_3proj_1cam.json"}) {
      for (const char* scene : {"plane", "sphere", "rgbcmy_panel", "statue", "bunny"}) {
        digestFrame(rig, scene);
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "demux_digest: %s\n", e.what());
    return 1;
  }
  return 0;
}
