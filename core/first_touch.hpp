// SPDX-License-Identifier: MIT
/// @file Filling and copying large arrays with the rows over core/parallel's threads, so that the
/// pages of a fresh allocation are first touched by all threads instead of one.
///
/// Memory a process touches for the first time costs a page fault per page: the kernel maps and
/// clears it (and on a virtual machine the host may have to back it too): writing fresh pages is
/// several times slower than writing pages already mapped, and faster with more threads. A fine
/// level touches gigabytes of new memory, so the large arrays that the set-up and the first
/// solves allocate are filled here.
/// Elementwise: the values are those of std::fill / std::copy, whichever thread writes them.
#pragma once

#include "core/parallel.hpp"
#include "core/types.hpp"

#include <algorithm>
#include <cstddef>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace mlc::parallel {

/// Smallest chunk of a fill or copy (elements): below it a loop runs on the caller alone.
inline constexpr std::size_t kTouchRowsPerChunk = std::size_t{1} << 15;

/// p[0, n) = value, with the rows over the threads.
template <class T> void fill(T* p, std::size_t n, const T& value) {
    for_rows(n, kTouchRowsPerChunk,
             [&](std::size_t b, std::size_t e) { std::fill(p + b, p + e, value); });
}

/// dst[0, n) = src[0, n) (the ranges must not overlap), with the rows over the threads.
template <class T> void copy(const T* src, std::size_t n, T* dst) {
    for_rows(n, kTouchRowsPerChunk,
             [&](std::size_t b, std::size_t e) { std::copy(src + b, src + e, dst + b); });
}

/// A vector of n zeros whose pages were first touched by all threads (Vector::Zero(n) writes
/// them all from the calling thread).
inline Vector zeros(Index n) {
    Vector v(n);
    fill(v.data(), static_cast<std::size_t>(n), 0.0);
    return v;
}

/// v = 0 at size n, with the rows over the threads (v.setZero(n) on one thread).
inline void set_zero(Vector& v, Index n) {
    v.resize(n);
    fill(v.data(), static_cast<std::size_t>(n), 0.0);
}

/// std::allocator whose value-less construct default-initialises: `resize` of a vector of
/// doubles or floats then writes nothing, and the (parallel) loop that first writes the elements
/// decides which threads touch the pages (a std::vector<T> writes zeros from one thread).
template <class T> struct DefaultInitAllocator : std::allocator<T> {
    /// The same allocator for another value type (what std::allocator_traits asks for).
    template <class U> struct rebind { using other = DefaultInitAllocator<U>; };
    DefaultInitAllocator() noexcept = default;
    template <class U> DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept {}
    template <class U> void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
        ::new (static_cast<void*>(p)) U;
    }
    template <class U, class... Args> void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
};

/// A std::vector whose `resize` leaves new elements uninitialised (DefaultInitAllocator): for
/// arrays that a parallel loop fills completely before anything reads them.
template <class T> using UninitializedVector = std::vector<T, DefaultInitAllocator<T>>;

/// An array of n uninitialised T (new T[n]: no value is written, so the loop that first writes it
/// decides which threads touch its pages; std::vector<T>(n) writes zeros from one thread).
template <class T> std::unique_ptr<T[]> uninitialized_array(std::size_t n) {
    return std::unique_ptr<T[]>(new T[n]);
}

} // namespace mlc::parallel
