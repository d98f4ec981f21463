// Springs as parallel arrays (spring_list.hpp).
#include "flexfit/spring_list.hpp"

#include "flexfit/part_model.hpp"

namespace flexfit {

void SpringList::clear() {
    springA.clear();
    springB.clear();
    restLength.clear();
    stiffness.clear();
    damping.clear();
}

void SpringList::reserve(std::size_t springs) {
    springA.reserve(springs);
    springB.reserve(springs);
    restLength.reserve(springs);
    stiffness.reserve(springs);
    damping.reserve(springs);
}

void SpringList::append(Index a, Index b, double rest, double k, double c) {
    springA.push_back(a);
    springB.push_back(b);
    restLength.push_back(rest);
    stiffness.push_back(k);
    damping.push_back(c);
}

void SpringList::append(const PartModel& model, Index e) {
    append(model.springA[e], model.springB[e], model.restLength[e], model.stiffness[e], model.damping[e]);
}

void SpringList::moveLastTo(std::size_t slot) {
    springA[slot] = springA.back();
    springB[slot] = springB.back();
    restLength[slot] = restLength.back();
    stiffness[slot] = stiffness.back();
    damping[slot] = damping.back();
    springA.pop_back();
    springB.pop_back();
    restLength.pop_back();
    stiffness.pop_back();
    damping.pop_back();
}

SpringList springListOf(const PartModel& model, std::span<const Index> springs) {
    SpringList list;
    list.reserve(springs.size());
    for (const Index e : springs) list.append(model, e);
    return list;
}

}  // namespace flexfit
