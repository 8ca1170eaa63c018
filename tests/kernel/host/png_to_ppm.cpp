// png_to_ppm IN.png OUT.ppm: a rendered camera image as the binary PPM that the guest's
// vivid_loop_feed reads (the guest has no PNG library).
#include <cstdio>

#include "ppm_io.hpp"
#include "smx/sim/png_io.hpp"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: png_to_ppm IN.png OUT.ppm\n");
    return 2;
  }
  auto image = smx::sim::readPngRgb8(argv[1]);
  if (!image) {
    std::fprintf(stderr, "png_to_ppm: %s\n", image.error().c_str());
    return 1;
  }
  if (auto written = smx::test::writePpm(argv[2], image->view()); !written) {
    std::fprintf(stderr, "png_to_ppm: %s\n", written.error().c_str());
    return 1;
  }
  return 0;
}
