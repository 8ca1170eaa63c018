// A QEMU TCG plugin that counts the guest instructions a process executes and prints
// "insns: <count>" when it exits (docs/arm-cost.md). For the dynamic qemu-aarch64 of Debian 12
// (QEMU 7.2, plugin API version 1): qemu-aarch64 -L / -plugin ./libinsn_count_plugin.so
// -d plugin PROGRAM. Debian ships no qemu-plugin.h, so the few declarations used are written
// out here from the API of that version; they are resolved against the qemu binary at load.
// With the argument `blocks=on` (-plugin ./libinsn_count_plugin.so,blocks=on) it also prints
// "block: <guest address> <instructions>" per translation block executed, for a profile by
// function (tests/armcost/profile-instructions).
//
// Each translation block gets an inline add of its instruction count (no helper call per
// block), and with `blocks=on` one of 1 to its own execution count. The adds are not atomic: exact
// for a single-threaded guest, which pipeline_frames is.
#include <cinttypes>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <deque>

// NOLINTBEGIN(readability-identifier-naming): the names are QEMU's.
extern "C" {

using qemu_plugin_id_t = std::uint64_t;
struct qemu_plugin_tb;  // opaque
struct qemu_info_t;     // only passed through

enum qemu_plugin_op : int { QEMU_PLUGIN_INLINE_ADD_U64 = 0 };

using qemu_plugin_vcpu_tb_trans_cb_t = void (*)(qemu_plugin_id_t id, qemu_plugin_tb* tb);
using qemu_plugin_udata_cb_t = void (*)(qemu_plugin_id_t id, void* userdata);

std::uint64_t qemu_plugin_tb_vaddr(const qemu_plugin_tb* tb);

void qemu_plugin_register_vcpu_tb_trans_cb(qemu_plugin_id_t id, qemu_plugin_vcpu_tb_trans_cb_t cb);
void qemu_plugin_register_vcpu_tb_exec_inline(qemu_plugin_tb* tb, qemu_plugin_op op, void* ptr,
                                              std::uint64_t imm);
std::size_t qemu_plugin_tb_n_insns(const qemu_plugin_tb* tb);
void qemu_plugin_register_atexit_cb(qemu_plugin_id_t id, qemu_plugin_udata_cb_t cb, void* userdata);
void qemu_plugin_outs(const char* string);

// QEMU refuses a plugin without this symbol or with a version it does not support.
__attribute__((visibility("default"))) extern const int qemu_plugin_version;
const int qemu_plugin_version = 1;

__attribute__((visibility("default"))) int qemu_plugin_install(qemu_plugin_id_t id,
                                                               const qemu_info_t* info, int argc,
                                                               char** argv);

}  // extern "C"
// NOLINTEND(readability-identifier-naming)

namespace {

std::uint64_t insnCount = 0;

struct Block {
  std::uint64_t address;
  std::uint64_t insns;
  std::uint64_t executions;
};
bool profileBlocks = false;
std::deque<Block> blocks;  // stable addresses for the inline adds

void onTranslate(qemu_plugin_id_t /*id*/, qemu_plugin_tb* tb) {
  const std::size_t n = qemu_plugin_tb_n_insns(tb);
  qemu_plugin_register_vcpu_tb_exec_inline(tb, QEMU_PLUGIN_INLINE_ADD_U64, &insnCount, n);
  if (profileBlocks) {
    Block& b = blocks.emplace_back(Block{qemu_plugin_tb_vaddr(tb), n, 0});
    qemu_plugin_register_vcpu_tb_exec_inline(tb, QEMU_PLUGIN_INLINE_ADD_U64, &b.executions, 1);
  }
}

void onExit(qemu_plugin_id_t /*id*/, void* /*userdata*/) {
  char line[80];
  for (const Block& b : blocks) {
    if (b.executions != 0) {
      std::snprintf(line, sizeof line, "block: %" PRIx64 " %" PRIu64 "\n", b.address,
                    b.insns * b.executions);
      qemu_plugin_outs(line);
    }
  }
  std::snprintf(line, sizeof line, "insns: %" PRIu64 "\n", insnCount);
  qemu_plugin_outs(line);
}

}  // namespace

int qemu_plugin_install(qemu_plugin_id_t id, const qemu_info_t* /*info*/, int argc, char** argv) {
  if (argc == 1 && std::strcmp(argv[0], "blocks=on") == 0) {
    profileBlocks = true;
  } else if (argc != 0) {
    qemu_plugin_outs("insn_count_plugin: the only argument is blocks=on\n");
    return -1;
  }
  qemu_plugin_register_vcpu_tb_trans_cb(id, onTranslate);
  qemu_plugin_register_atexit_cb(id, onExit, nullptr);
  return 0;
}
