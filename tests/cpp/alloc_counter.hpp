#pragma once
// Counts heap allocations made through global operator new/malloc-backed new in this process.
// The replacement operators live in alloc_counter.cpp, linked into every C++ test executable.
#include <atomic>
#include <cstddef>

namespace mechbal::test {

std::size_t allocation_count() noexcept;

/// Number of allocations since construction.
class AllocationScope {
 public:
  AllocationScope() noexcept : start_(allocation_count()) {}
  std::size_t count() const noexcept { return allocation_count() - start_; }

 private:
  std::size_t start_;
};

}  // namespace mechbal::test
