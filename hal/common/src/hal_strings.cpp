#include "smx/hal/camera.hpp"
#include "smx/hal/error.hpp"

namespace smx::hal {

const char* toString(HalErrc code) {
  switch (code) {
    case HalErrc::kTimeout:
      return "timeout";
    case HalErrc::kDisconnected:
      return "disconnected";
    case HalErrc::kBusy:
      return "busy";
    case HalErrc::kInvalidState:
      return "invalid state";
    case HalErrc::kInvalidArgument:
      return "invalid argument";
    case HalErrc::kNotSupported:
      return "not supported";
    case HalErrc::kIo:
      return "I/O error";
  }
  return "unknown error";
}

std::string_view toString(PixelFormat format) {
  switch (format) {
    case PixelFormat::kRgb24:
      return "RGB24";
    case PixelFormat::kBgr24:
      return "BGR24";
    case PixelFormat::kYuyv:
      return "YUYV";
  }
  return "unknown";
}

}  // namespace smx::hal
