// A fixed-size array of zero-initialised trivially copyable values whose memory the system
// commits page by page, where it is first written (internal).
//
// A search reads and writes its per-cell state by cell index, with no indirection in the inner
// loops, yet holds memory only for the pages it has touched: reserving the array commits nothing
// (an anonymous mapping, 4 KiB pages, zero until written), so a map of 16 million cells costs a
// short query a few pages, not 16 million records. Pages stay committed for the next query (the
// searches reset their state by epoch, not by clearing), and release() hands them all back in
// O(1) writes, zero again: what the epoch counters do when they wrap.
//
// On systems without anonymous mappings it falls back to std::calloc, which commits lazily where
// the C library maps large blocks (glibc does above its mmap threshold).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <new>
#include <type_traits>
#include <utility>

#if defined(__unix__) || defined(__APPLE__)
#include <sys/mman.h>
#include <unistd.h>
#define VNSBA_LAZY_ARRAY_MMAP 1
#endif

namespace vnsba::core::detail {

template <class T>
class LazyArray {
  static_assert(std::is_trivially_copyable_v<T>, "pages are zero-filled, never constructed");

 public:
  LazyArray() = default;
  ~LazyArray() { reset(); }
  LazyArray(LazyArray&& other) noexcept
      : data_(std::exchange(other.data_, nullptr)), size_(std::exchange(other.size_, 0)) {}
  LazyArray& operator=(LazyArray&& other) noexcept {
    if (this != &other) {
      reset();
      data_ = std::exchange(other.data_, nullptr);
      size_ = std::exchange(other.size_, 0);
    }
    return *this;
  }
  LazyArray(const LazyArray&) = delete;
  LazyArray& operator=(const LazyArray&) = delete;

  // Makes the array `size` values long, all zero (a no-op when it already is that long, keeping
  // its values). Throws std::bad_alloc when the address space cannot be reserved.
  void resize(size_t size) {
    if (size == size_) return;
    reset();
    if (size == 0) return;
#ifdef VNSBA_LAZY_ARRAY_MMAP
    void* p = mmap(nullptr, size * sizeof(T), PROT_READ | PROT_WRITE,
                   MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
    if (p == MAP_FAILED) throw std::bad_alloc();
#else
    void* p = std::calloc(size, sizeof(T));
    if (p == nullptr) throw std::bad_alloc();
#endif
    data_ = static_cast<T*>(p);
    size_ = size;
  }

  // Every value zero again, and every page handed back to the system.
  void release() {
    if (data_ == nullptr) return;
#ifdef VNSBA_LAZY_ARRAY_MMAP
    // On an anonymous private mapping the pages read as zero afterwards.
    if (madvise(data_, size_ * sizeof(T), MADV_DONTNEED) == 0) return;
#endif
    std::memset(static_cast<void*>(data_), 0, size_ * sizeof(T));
  }

  size_t size() const {
    return size_;
  }
  T& operator[](size_t i) {
    return data_[i];
  }
  const T& operator[](size_t i) const {
    return data_[i];
  }

  // Bytes committed: the pages written since the last release() (the reserved size where the
  // system cannot tell). O(pages reserved); for reports, not for the inner loops.
  size_t resident_bytes() const {
    if (data_ == nullptr) return 0;
#ifdef VNSBA_LAZY_ARRAY_MMAP
    const size_t page = static_cast<size_t>(sysconf(_SC_PAGESIZE));
    const size_t pages = (size_ * sizeof(T) + page - 1) / page;
    constexpr size_t kChunk = 4096;  // pages asked about per call
    unsigned char residency[kChunk];
    size_t resident = 0;
    for (size_t first = 0; first < pages; first += kChunk) {
      const size_t count = std::min(kChunk, pages - first);
      if (mincore(reinterpret_cast<char*>(data_) + first * page, count * page, residency) != 0)
        return size_ * sizeof(T);
      for (size_t i = 0; i < count; ++i) resident += residency[i] & 1;
    }
    return resident * page;
#else
    return size_ * sizeof(T);
#endif
  }

 private:
  void reset() {
    if (data_ == nullptr) return;
#ifdef VNSBA_LAZY_ARRAY_MMAP
    munmap(data_, size_ * sizeof(T));
#else
    std::free(data_);
#endif
    data_ = nullptr;
    size_ = 0;
  }

  T* data_ = nullptr;
  size_t size_ = 0;
};

}  // namespace vnsba::core::detail
