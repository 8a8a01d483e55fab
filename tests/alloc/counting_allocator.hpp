// A counting allocator for the tests under tests/alloc: a global operator
// new/delete and, for Eigen (which calls std::malloc directly), wrapped
// malloc/calloc/realloc; the executable that includes this header (in exactly
// one source file) is linked with -Wl,--wrap=malloc,--wrap=calloc,--wrap=realloc.
// Count counts the allocations made while it lives.
#pragma once

#include <atomic>
#include <cstdlib>
#include <new>

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};
}  // namespace

void* operator new(std::size_t n) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
// Eigen allocates with std::malloc directly (its storage is aligned by the
// platform's malloc), not with operator new: this executable is linked with
// --wrap=malloc,calloc,realloc so that calls from codyna's code and the Eigen
// code instantiated in it are counted too.
extern "C" {
void* __real_malloc(std::size_t);
void* __real_calloc(std::size_t, std::size_t);
void* __real_realloc(void*, std::size_t);
void* __wrap_malloc(std::size_t n) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __real_malloc(n);
}
void* __wrap_calloc(std::size_t n, std::size_t s) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __real_calloc(n, s);
}
void* __wrap_realloc(void* p, std::size_t n) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __real_realloc(p, n);
}
}

namespace codyna::alloc_test {

struct Count {
  Count() {
    g_allocations = 0;
    g_counting = true;
  }
  ~Count() { g_counting = false; }
  long n() const { return g_allocations.load(); }
};

}  // namespace codyna::alloc_test
