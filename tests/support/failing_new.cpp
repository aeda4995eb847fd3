// Preloaded (LD_PRELOAD) into a process under test: while the file named by
// FOOTFALL_FAIL_NEW_WHILE exists, every FOOTFALL_FAIL_NEW_EVERY-th C++ allocation (operator new,
// in any thread) fails as it does when memory runs out: std::bad_alloc, or nullptr from the
// nothrow forms. The file may hold a number K: the first K allocations after it appears succeed
// (a test moves the first failure through a call). With FOOTFALL_FAIL_NEW_AFTER=N instead of a
// file, failures start after the process's first N allocations (the same point at every run of a
// single-threaded program: a sweep over N fails each allocation in turn). With
// FOOTFALL_FAIL_NEW_IN_MAIN=1 too, N counts from the moment main is called: the static
// constructors before it (libraries', where a failure ends any program) neither fail nor count, so
// the same N names the same allocation of the program's own startup whatever they make. Checks
// that a process keeps its promises when memory runs short, anywhere.
#include <dlfcn.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <new>

namespace {

using MainFunction = int (*)(int, char**, char**);
MainFunction g_main = nullptr;
std::atomic<bool> g_in_main{false};
std::atomic<unsigned long> g_made{0};  // allocations counted (FOOTFALL_FAIL_NEW_AFTER)

// The program's main, after marking that it runs (FOOTFALL_FAIL_NEW_IN_MAIN counts from here).
int CountedMain(int argc, char** argv, char** envp) {
  g_in_main.store(true);
  return g_main(argc, argv, envp);
}

// Whether this allocation fails. Reads the environment once; makes no C++ allocation.
bool FailNow() {
  static const char* const flag = std::getenv("FOOTFALL_FAIL_NEW_WHILE");
  static const long every = [] {
    const char* text = std::getenv("FOOTFALL_FAIL_NEW_EVERY");
    const long n = text ? std::atol(text) : 0;
    return n > 0 ? n : 1;
  }();
  static const long after = [] {
    const char* text = std::getenv("FOOTFALL_FAIL_NEW_AFTER");
    return text ? std::atol(text) : -1;
  }();
  static const bool in_main_only = [] {
    const char* text = std::getenv("FOOTFALL_FAIL_NEW_IN_MAIN");
    return text && text[0] == '1';
  }();
  static std::atomic<unsigned long> count{0};
  if (after >= 0) {
    if (in_main_only && !g_in_main.load()) return false;
    const unsigned long n = g_made.fetch_add(1, std::memory_order_relaxed);
    if (n < static_cast<unsigned long>(after)) return false;
    return (n - static_cast<unsigned long>(after)) % static_cast<unsigned long>(every) == 0;
  }
  static std::atomic<long> skip{0};
  static std::atomic<long long> seen{-1};  // the flag file last seen (its inode and mtime)
  struct stat st;
  if (!flag || stat(flag, &st) != 0) {
    count.store(0, std::memory_order_relaxed);  // from the start again when the file comes back
    return false;
  }
  // A file made again since the last allocation (none happened while it was gone, an idle
  // server's case) counts from the start too.
  const long long stamp = static_cast<long long>(st.st_ino) * 1000003 +
                          st.st_mtim.tv_sec * 1000000000LL + st.st_mtim.tv_nsec;
  if (seen.exchange(stamp) != stamp) count.store(0, std::memory_order_relaxed);
  const unsigned long n = count.fetch_add(1, std::memory_order_relaxed);
  if (n == 0) {
    // The file may hold a number: that many allocations succeed first.
    long first = 0;
    if (FILE* f = std::fopen(flag, "r")) {
      if (std::fscanf(f, "%ld", &first) != 1) first = 0;
      std::fclose(f);
    }
    skip.store(first, std::memory_order_relaxed);
  }
  const long first = skip.load(std::memory_order_relaxed);
  if (static_cast<long>(n) < first) return false;
  return (n - static_cast<unsigned long>(first)) % static_cast<unsigned long>(every) == 0;
}

void* Allocate(std::size_t size) {
  if (FailNow()) return nullptr;
  return std::malloc(size == 0 ? 1 : size);
}

void* AllocateAligned(std::size_t size, std::align_val_t align) {
  if (FailNow()) return nullptr;
  const std::size_t a = static_cast<std::size_t>(align);
  const std::size_t rounded = (size + a - 1) / a * a;
  return std::aligned_alloc(a, rounded == 0 ? a : rounded);
}

}  // namespace

// Interposed on the C library's (which every dynamically linked program's entry calls with its
// main): hands it CountedMain instead.
extern "C" int __libc_start_main(MainFunction main, int argc, char** argv, void (*init)(),
                                 void (*fini)(), void (*rtld_fini)(), void* stack_end) {
  using Start = int (*)(MainFunction, int, char**, void (*)(), void (*)(), void (*)(), void*);
  const auto start = reinterpret_cast<Start>(dlsym(RTLD_NEXT, "__libc_start_main"));
  if (!start) {
    std::fputs("failing_new: no __libc_start_main to call\n", stderr);
    std::_Exit(127);
  }
  g_main = main;
  return start(CountedMain, argc, argv, init, fini, rtld_fini, stack_end);
}

void* operator new(std::size_t size) {
  if (void* p = Allocate(size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) {
  if (void* p = Allocate(size)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t size, const std::nothrow_t&) noexcept { return Allocate(size); }
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept { return Allocate(size); }
void* operator new(std::size_t size, std::align_val_t align) {
  if (void* p = AllocateAligned(size, align)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size, std::align_val_t align) {
  if (void* p = AllocateAligned(size, align)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
