// The vocabulary (names.hpp, and the table beside each enum): every table lists each value of
// its enum once under a distinct name, every name reads back as its value, toString is the
// name, and the old spellings read as their values with the new name to write.
#include "flexfit/flexfit.hpp"

#include <gtest/gtest.h>

#include <set>
#include <string>

using namespace flexfit;

namespace {

template <class Enum>
void expectOneNamePerValue(int valueCount) {
    const auto names = enumNames<Enum>();
    ASSERT_EQ(int(names.size()), valueCount);
    std::set<std::string> seen;
    for (int v = 0; v < valueCount; ++v) {
        const Enum value = Enum(v);
        EXPECT_EQ(names[std::size_t(v)].value, value) << "tables follow declaration order";
        const std::string name = nameOf(value);
        EXPECT_TRUE(seen.insert(name).second) << "name '" << name << "' twice";
        EXPECT_EQ(std::string(toString(value)), name);
        EXPECT_FALSE(std::string(labelOf(value)).empty());
        std::string replacement = "unchanged";
        EXPECT_EQ(parseName<Enum>(name, &replacement), value);
        EXPECT_TRUE(replacement.empty());
    }
    EXPECT_EQ(parseName<Enum>("no such name"), std::nullopt);
    for (const auto& old : deprecatedNames<Enum>()) EXPECT_FALSE(seen.count(old.name)) << old.name << " is both old and current";
}

}  // namespace

TEST(Names, EveryEnumHasOneNamePerValue) {
    expectOneNamePerValue<PartMode>(3);
    expectOneNamePerValue<MotionType>(3);
    expectOneNamePerValue<Integrator>(3);
    expectOneNamePerValue<RestorationMethod>(3);
    expectOneNamePerValue<ExactTest>(2);
    expectOneNamePerValue<BoundingVolumeKind>(2);
    expectOneNamePerValue<BroadPhaseUpdate>(2);
    expectOneNamePerValue<RigidDeformableQuery>(3);
    expectOneNamePerValue<SnapTechnique>(4);
    expectOneNamePerValue<AssemblyArea::Shape>(3);
    expectOneNamePerValue<SceneAction::Kind>(7);
    expectOneNamePerValue<Stage>(int(kStageCount));
}

TEST(Names, OldSpellingsReadAsTheirValueWithTheNewName) {
    std::string replacement;
    EXPECT_EQ(parseName<RestorationMethod>("anchor", &replacement), RestorationMethod::AnchorSprings);
    EXPECT_EQ(replacement, "anchors");
    EXPECT_EQ(parseName<PartMode>("zones", &replacement), PartMode::RigidDeformable);
    EXPECT_EQ(replacement, "rigid-deformable");
    EXPECT_EQ(parseName<PartMode>("full", &replacement), PartMode::FullDeformable);
    EXPECT_EQ(replacement, "full-deformable");
    EXPECT_EQ(deprecationWarning("anchor", "anchors"), "'anchor' is deprecated: write 'anchors'");
}

TEST(Names, ListsForMessagesAndChoices) {
    EXPECT_EQ(nameList<RestorationMethod>(), "'none', 'anchors', 'constraint'");
    EXPECT_EQ(allNames<PartMode>(), (std::vector<std::string>{"rigid", "rigid-deformable", "full-deformable"}));
    EXPECT_EQ(allNames<PartMode>(true), (std::vector<std::string>{"rigid", "rigid-deformable", "full-deformable", "zones", "full"}));
}
