#pragma once

#include <string>
#include <string_view>

// Text from outside (a device's answers, file contents, file names) on the user's terminal.
namespace smx::host {

// `text` with every byte that could steer a terminal shown as \xNN instead: C0 controls, DEL, the
// UTF-8 encodings of the C1 controls (U+0080 to U+009F, which include CSI and OSC) and bytes that
// are not UTF-8. Printable UTF-8 passes unchanged.
[[nodiscard]] std::string printable(std::string_view text);

}  // namespace smx::host
