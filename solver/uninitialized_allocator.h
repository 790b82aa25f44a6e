#pragma once
/// An allocator whose value-initialising construct (what vector::resize(n)
/// calls for each new element) does nothing: the new elements' storage is
/// left as it is, for buffers that are written in full right after they
/// grow. The point is the pages: resize(n) on a fresh buffer of 10^7
/// elements writes (and so faults in, one thread) half a gigabyte that the
/// next loop overwrites anyway; left untouched, the pages are first touched
/// by the loop that fills them, in parallel where it runs in parallel.
///
/// Only for implicit-lifetime types (aggregates of scalars: C++20 makes
/// their objects exist in allocated storage without a constructor call),
/// and only where every new element is assigned before it is read. Copies,
/// push_back and insert construct as usual.
#include <memory>
#include <type_traits>
#include <utility>

namespace flatrad {

template <class T>
struct UninitializedAllocator : std::allocator<T> {
    static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>,
                  "left uninitialised only where copying and destroying are trivial");
    template <class U>
    struct rebind {
        using other = UninitializedAllocator<U>;
    };
    UninitializedAllocator() = default;
    template <class U>
    UninitializedAllocator(const UninitializedAllocator<U>&) noexcept {}

    /// vector::resize(n): no value written.
    template <class U>
    void construct(U*) noexcept {}
    template <class U, class... Args>
    void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
};

template <class T, class U>
bool operator==(const UninitializedAllocator<T>&, const UninitializedAllocator<U>&) noexcept {
    return true;
}

}  // namespace flatrad
