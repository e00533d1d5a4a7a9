// Dermis core — disjoint sets (union–find with path halving) over indices 0…n−1: the connected
// pieces of UV islands (uv_lookup, uv_diagnosis), of layout charts (layout_check) and of chart
// corners (the default character's atlas). Header-only, no allocation but the parent array.
#pragma once

#include <cstddef>
#include <numeric>
#include <vector>

namespace dermis {

class DisjointSets {
public:
    /// n singleton sets {0}, …, {n−1}.
    explicit DisjointSets(std::size_t n = 0) : parent_(n) { std::iota(parent_.begin(), parent_.end(), std::size_t(0)); }

    /// Adds the singleton set {size()}; returns its index.
    std::size_t add() {
        parent_.push_back(parent_.size());
        return parent_.size() - 1;
    }
    std::size_t size() const { return parent_.size(); }

    /// The representative of v's set. Precondition: v < size().
    std::size_t root(std::size_t v) {
        while (parent_[v] != v) v = parent_[v] = parent_[parent_[v]];
        return v;
    }
    /// Merges the sets of a and b under b's representative.
    void join(std::size_t a, std::size_t b) { parent_[root(a)] = root(b); }
    /// Merges the sets of a and b under the smaller representative, so that every set's
    /// representative is its smallest member whatever the order of the merges.
    void joinToSmaller(std::size_t a, std::size_t b) {
        a = root(a);
        b = root(b);
        if (a < b) parent_[b] = a;
        else if (b < a) parent_[a] = b;
    }

private:
    std::vector<std::size_t> parent_;
};

} // namespace dermis
