// Internal: room for `count` elements, grown geometrically. For registries that reserve one more
// before each add so that the add cannot throw past that point (World::add, CollisionWorld::add):
// an exact reserve there moved every element on every add, quadratic in the number of parts.
#pragma once

#include <algorithm>
#include <cstddef>

namespace flexfit::detail {

template <class Vector>
void reserveGrowing(Vector& v, std::size_t count) {
    if (v.capacity() < count) v.reserve(std::max(count, 2 * v.capacity()));
}

}  // namespace flexfit::detail
