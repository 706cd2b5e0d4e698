#include "memory_meter.h"

#include <LinearMath/btAlignedAllocator.h>

#include <cstdlib>
#include <new>

namespace kolize::bench {
namespace {

// Single-threaded programs: plain counters.
std::size_t current = 0;
std::size_t peak = 0;
std::size_t baseline = 0;
// A 16-byte header keeps the block 16-byte aligned, as malloc's is.
constexpr std::size_t kHeader = 16;

void* countedAlloc(std::size_t size) {
    auto* block = static_cast<unsigned char*>(std::malloc(size + kHeader));
    if (block == nullptr) {
        return nullptr;
    }
    *reinterpret_cast<std::size_t*>(block) = size;
    current += size;
    if (current > peak) {
        peak = current;
    }
    return block + kHeader;
}

void countedFree(void* memory) {
    if (memory == nullptr) {
        return;
    }
    auto* block = static_cast<unsigned char*>(memory) - kHeader;
    current -= *reinterpret_cast<std::size_t*>(block);
    std::free(block);
}

}  // namespace

void countBulletAllocations() {
    btAlignedAllocSetCustom(countedAlloc, countedFree);
}
std::size_t currentBytes() {
    return current;
}
void resetPeak() {
    peak = current;
    baseline = current;
}
std::size_t peakBytesSinceReset() {
    return peak - baseline;
}

}  // namespace kolize::bench

void* operator new(std::size_t size) {
    void* memory = kolize::bench::countedAlloc(size == 0 ? 1 : size);
    if (memory == nullptr) {
        throw std::bad_alloc();
    }
    return memory;
}
void* operator new[](std::size_t size) {
    return operator new(size);
}
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
    return kolize::bench::countedAlloc(size == 0 ? 1 : size);
}
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
    return kolize::bench::countedAlloc(size == 0 ? 1 : size);
}
void operator delete(void* memory) noexcept {
    kolize::bench::countedFree(memory);
}
void operator delete[](void* memory) noexcept {
    kolize::bench::countedFree(memory);
}
void operator delete(void* memory, std::size_t) noexcept {
    kolize::bench::countedFree(memory);
}
void operator delete[](void* memory, std::size_t) noexcept {
    kolize::bench::countedFree(memory);
}
