#include "alloc_counter.hpp"

#include <atomic>
#include <cerrno>
#include <cstddef>
#include <cstdlib>
#include <new>

namespace {

std::atomic<std::uint64_t> gAllocations{0};
std::atomic<std::uint64_t> gBytes{0};

void noteAllocation(std::size_t bytes) {
  gAllocations.fetch_add(1, std::memory_order_relaxed);
  gBytes.fetch_add(bytes, std::memory_order_relaxed);
}

}  // namespace

namespace smx::test {

std::uint64_t allocationsSoFar() {
  return gAllocations.load(std::memory_order_relaxed);
}
std::uint64_t bytesAllocatedSoFar() {
  return gBytes.load(std::memory_order_relaxed);
}

}  // namespace smx::test

#if defined(SMX_ALLOC_COUNTER_SANITIZER_HOOKS)

// Declared here: GCC's sanitizer runtime exports it, but Debian's GCC ships no
// <sanitizer/allocator_interface.h>.
extern "C" int __sanitizer_install_malloc_and_free_hooks(  // NOLINT(bugprone-reserved-identifier)
    void (*mallocHook)(const volatile void*, std::size_t), void (*freeHook)(const volatile void*));

namespace {

void onMalloc(const volatile void* /*ptr*/, std::size_t bytes) {
  noteAllocation(bytes);
}
void onFree(const volatile void* /*ptr*/) {}

// Installed before main; the hooks stay for the life of the process.
[[maybe_unused]] const int gHooksInstalled =
    __sanitizer_install_malloc_and_free_hooks(onMalloc, onFree);

}  // namespace

#else

// glibc's allocator under its internal names: the replacements below count, then forward, so
// memory allocated anywhere (glibc itself included) is freed by the same allocator.
extern "C" {
void* __libc_malloc(std::size_t);                 // NOLINT(bugprone-reserved-identifier)
void* __libc_calloc(std::size_t, std::size_t);    // NOLINT(bugprone-reserved-identifier)
void* __libc_realloc(void*, std::size_t);         // NOLINT(bugprone-reserved-identifier)
void* __libc_memalign(std::size_t, std::size_t);  // NOLINT(bugprone-reserved-identifier)
void __libc_free(void*);                          // NOLINT(bugprone-reserved-identifier)

void* malloc(std::size_t bytes) {
  noteAllocation(bytes);
  return __libc_malloc(bytes);
}
void* calloc(std::size_t count, std::size_t size) {
  noteAllocation(count * size);
  return __libc_calloc(count, size);
}
void* realloc(void* ptr, std::size_t bytes) {
  noteAllocation(bytes);
  return __libc_realloc(ptr, bytes);
}
void* memalign(std::size_t alignment, std::size_t bytes) {
  noteAllocation(bytes);
  return __libc_memalign(alignment, bytes);
}
void* aligned_alloc(std::size_t alignment, std::size_t bytes) {
  noteAllocation(bytes);
  return __libc_memalign(alignment, bytes);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t bytes) {
  if (alignment < sizeof(void*) || (alignment & (alignment - 1)) != 0) {
    return EINVAL;
  }
  noteAllocation(bytes);
  void* p = __libc_memalign(alignment, bytes);
  if (p == nullptr) {
    return ENOMEM;
  }
  *out = p;
  return 0;
}
void free(void* ptr) {
  __libc_free(ptr);
}
}  // extern "C"

namespace {

void* allocateOrThrow(std::size_t bytes, std::size_t alignment) {
  noteAllocation(bytes);
  void* p = alignment <= alignof(std::max_align_t) ? __libc_malloc(bytes == 0 ? 1 : bytes)
                                                   : __libc_memalign(alignment, bytes);
  if (p == nullptr) {
    throw std::bad_alloc();
  }
  return p;
}

void* allocateOrNull(std::size_t bytes, std::size_t alignment) noexcept {
  try {
    return allocateOrThrow(bytes, alignment);
  } catch (const std::bad_alloc&) {
    return nullptr;
  }
}

constexpr std::size_t kDefault = alignof(std::max_align_t);
std::size_t toSize(std::align_val_t a) {
  return static_cast<std::size_t>(a);
}

}  // namespace

// All replaceable global allocation functions ([new.delete]); the rest of the standard's
// variants forward to these.
void* operator new(std::size_t n) {
  return allocateOrThrow(n, kDefault);
}
void* operator new[](std::size_t n) {
  return allocateOrThrow(n, kDefault);
}
void* operator new(std::size_t n, std::align_val_t a) {
  return allocateOrThrow(n, toSize(a));
}
void* operator new[](std::size_t n, std::align_val_t a) {
  return allocateOrThrow(n, toSize(a));
}
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  return allocateOrNull(n, kDefault);
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
  return allocateOrNull(n, kDefault);
}
void* operator new(std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
  return allocateOrNull(n, toSize(a));
}
void* operator new[](std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
  return allocateOrNull(n, toSize(a));
}
void operator delete(void* p) noexcept {
  __libc_free(p);
}
void operator delete[](void* p) noexcept {
  __libc_free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  __libc_free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  __libc_free(p);
}
void operator delete(void* p, std::align_val_t) noexcept {
  __libc_free(p);
}
void operator delete[](void* p, std::align_val_t) noexcept {
  __libc_free(p);
}
void operator delete(void* p, std::size_t, std::align_val_t) noexcept {
  __libc_free(p);
}
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept {
  __libc_free(p);
}
void operator delete(void* p, const std::nothrow_t&) noexcept {
  __libc_free(p);
}
void operator delete[](void* p, const std::nothrow_t&) noexcept {
  __libc_free(p);
}
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept {
  __libc_free(p);
}
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept {
  __libc_free(p);
}

#endif
