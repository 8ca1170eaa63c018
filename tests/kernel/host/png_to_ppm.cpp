// png_to_ppm IN.png OUT.ppm: a rendered camera image as the binary PPM that the guest's
// vivid_loop_feed reads (the guest has no PNG library).
#include <cstdio>
#include <fstream>

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
  std::ofstream out(argv[2], std::ios::binary);
  out << "P6\n" << image->width << ' ' << image->height << "\n255\n";
  out.write(reinterpret_cast<const char*>(image->pixels.data()),
            static_cast<std::streamsize>(image->pixels.size() * sizeof(smx::algo::Rgb8)));
  if (!out) {
    std::fprintf(stderr, "png_to_ppm: cannot write %s\n", argv[2]);
    return 1;
  }
  return 0;
}
