// An allocator for large tables that asks the kernel for 2 MiB pages.
//
// Why: a table's memory is touched for the first time while it is built, and
// every 4 KiB page then costs a page fault.  On the virtual machines this
// project runs on a fault costs ~11 us (measured: writing 16 MiB of fresh
// 4 KiB pages took 45 ms, of fresh 2 MiB pages 0.7 ms), so the LUT sky's
// 14 MB of tables cost more in faults (~36 ms) than in arithmetic.
//
// Blocks of at least kHugePageMinBytes (1 MiB) are mapped on their own
// (mmap), start on a 2 MiB boundary, are rounded up to whole 2 MiB pages and
// are madvise(MADV_HUGEPAGE)d, so that with transparent huge pages in
// "madvise" or "always" mode the kernel backs them with 2 MiB pages (with
// THP off they are ordinary pages and cost what they did).  The rounding
// costs memory (a 4.2 MB table takes 6 MiB): mapped_bytes() says how much,
// and the tables report it in their memory_bytes().  Blocks of
// kOwnMappingMinBytes (256 KiB) up to 1 MiB are mapped on their own too,
// pre-faulted in one call; smaller ones come from operator new (glibc would
// otherwise mmap and unmap them, faulting every time).
//
// Freed blocks mapped on their own are kept for reuse, up to
// kRecycledMaxBytes (64 MiB) in all, and handed to the next request of the
// same mapped size (a table of the same resolution: the sky service builds
// the same tables again for every new sun or atmosphere); beyond that they
// are unmapped.  A reused block is already faulted in, and the kernel does
// not zero it again (zeroing fresh 2 MiB pages was ~5 % of a LUT build).
// Its old contents are not cleared, and elements constructed without a
// value are left unset (construct, below): a table that is not written in
// full must assign its values.  recycled_bytes() says how much is kept.
#pragma once
#include <cstddef>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace skyfarm {

inline constexpr std::size_t kOwnMappingMinBytes = std::size_t{256} << 10;
inline constexpr std::size_t kHugePageMinBytes = std::size_t{1} << 20;
inline constexpr std::size_t kRecycledMaxBytes = std::size_t{64} << 20;

// The bytes a block of `bytes` occupies (its mapping, for the blocks mapped on their own).
std::size_t mapped_bytes(std::size_t bytes);

// Maps a block of `bytes` (>= kOwnMappingMinBytes) as above; throws
// std::bad_alloc when the kernel refuses.  huge_page_unmap takes the same size.
void* huge_page_map(std::size_t bytes);
// (Or keeps it for reuse, as above.)
void huge_page_unmap(void* p, std::size_t bytes) noexcept;
// Bytes of freed blocks kept for reuse.
std::size_t recycled_bytes();

template <class T>
struct HugePageAllocator {
  using value_type = T;
  HugePageAllocator() = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    const std::size_t bytes = n * sizeof(T);
    if (bytes >= kOwnMappingMinBytes) return static_cast<T*>(huge_page_map(bytes));
    return static_cast<T*>(::operator new(bytes, std::align_val_t{alignof(T) > 64 ? alignof(T) : 64}));
  }
  void deallocate(T* p, std::size_t n) noexcept {
    const std::size_t bytes = n * sizeof(T);
    if (bytes >= kOwnMappingMinBytes)
      huge_page_unmap(p, bytes);
    else
      ::operator delete(p, std::align_val_t{alignof(T) > 64 ? alignof(T) : 64});
  }
  // Elements constructed without arguments are default-initialised, not
  // value-initialised: TableVector<float> v(n) or v.resize(n) leaves the
  // new floats unset (the builders write every value; zeroing 14 MB first
  // cost ~3 % of a LUT build).  assign(n, 0.0f) and v(n, x) still fill.
  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
  template <class U>
  bool operator==(const HugePageAllocator<U>&) const noexcept {
    return true;
  }
};

// A table's storage: a std::vector whose large blocks get 2 MiB pages.
template <class T>
using TableVector = std::vector<T, HugePageAllocator<T>>;

// What a table's storage occupies (its capacity's mapping).
template <class T>
std::size_t table_memory_bytes(const TableVector<T>& v) {
  return v.capacity() == 0 ? 0 : mapped_bytes(v.capacity() * sizeof(T));
}

}  // namespace skyfarm
