#pragma once
/// \file detail/link_subset.hpp
/// Internal: a set of links for the passes of detail/tree.hpp that can work on part of a tree.
#include <vector>

namespace mechbal::detail {

/// Some links closed under descendants (the subtrees of a few links: e.g. those a controller's
/// balancing joints move): one flag per link, and the flagged links in tree order (parents first).
struct LinkSubset {
  std::vector<unsigned char> member;
  std::vector<int> links;
};

}  // namespace mechbal::detail
