// One vocabulary: every enum a user names (in a scene file, on the command line, in JSON
// output or in the viewer) has one table of names, and all of them read it.
//
// Each value has one name, the spelling users type and read (scene files, CLI options,
// toString, JSON), and a label, words for prose and the viewer ("anchors" is named so and
// labelled "anchor springs"). Spellings that older versions accepted stay readable for a
// while: parseName() maps them to their value and says which name replaces them, so the
// caller can warn with the file and line.
//
// Each enum's header gives its table (kEnumNames<E>, and kDeprecatedNames<E> where old
// spellings exist); toString(value) returns the name for every enum that has one.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace flexfit {

template <class Enum>
struct EnumName {
    Enum value;
    const char* name;   // the one spelling
    const char* label;  // for prose and the viewer
};

template <class Enum>
struct DeprecatedName {
    const char* name;   // an old spelling, still read with a warning
    Enum value;
};

// The tables: every value once, in declaration order, each specialised in its enum's header
// right after the enum (so the names stand next to the values they name).
template <class Enum>
inline constexpr std::span<const EnumName<Enum>> kEnumNames{};
// Old spellings; none unless the enum's header gives some.
template <class Enum>
inline constexpr std::span<const DeprecatedName<Enum>> kDeprecatedNames{};

template <class Enum>
constexpr std::span<const EnumName<Enum>> enumNames() {
    static_assert(!kEnumNames<Enum>.empty(), "this enum has no table of names");
    return kEnumNames<Enum>;
}
template <class Enum>
constexpr std::span<const DeprecatedName<Enum>> deprecatedNames() {
    return kDeprecatedNames<Enum>;
}

// Whether `value` is one of the enum's values (an integer cast to it may be none).
template <class Enum>
constexpr bool isNamedValue(Enum value) {
    for (const EnumName<Enum>& e : enumNames<Enum>())
        if (e.value == value) return true;
    return false;
}

template <class Enum>
const EnumName<Enum>& entryOf(Enum value) {
    for (const EnumName<Enum>& e : enumNames<Enum>())
        if (e.value == value) return e;
    return enumNames<Enum>().front();  // unreachable for a valid value: each table lists every value
}

template <class Enum>
const char* nameOf(Enum value) {
    return entryOf(value).name;
}

template <class Enum>
const char* labelOf(Enum value) {
    return entryOf(value).label;
}

// The name of any value whose enum has a table.
template <class Enum>
    requires(!kEnumNames<Enum>.empty())
const char* toString(Enum value) {
    return nameOf(value);
}

// The value named `text`, or nullopt. For an old spelling, `replacement` (when given)
// receives the name to write instead; it is left empty otherwise.
template <class Enum>
std::optional<Enum> parseName(std::string_view text, std::string* replacement = nullptr) {
    if (replacement != nullptr) replacement->clear();
    for (const EnumName<Enum>& e : enumNames<Enum>())
        if (text == e.name) return e.value;
    for (const DeprecatedName<Enum>& d : deprecatedNames<Enum>())
        if (text == d.name) {
            if (replacement != nullptr) *replacement = nameOf(d.value);
            return d.value;
        }
    return std::nullopt;
}

// "'a', 'b', 'c'": the names, for messages.
template <class Enum>
std::string nameList() {
    std::string list;
    for (const EnumName<Enum>& e : enumNames<Enum>()) list += (list.empty() ? "'" : ", '") + std::string(e.name) + "'";
    return list;
}

// The names (and, with `withDeprecated`, the old spellings): for a CLI's list of choices.
template <class Enum>
std::vector<std::string> allNames(bool withDeprecated = false) {
    std::vector<std::string> out;
    for (const EnumName<Enum>& e : enumNames<Enum>()) out.emplace_back(e.name);
    if (withDeprecated)
        for (const DeprecatedName<Enum>& d : deprecatedNames<Enum>()) out.emplace_back(d.name);
    return out;
}

// For settings checks: throws Error(source, 0, problem) (InputError, core.hpp) unless
// isNamedValue(value), naming the integer and the values.
template <class Error, class Enum>
void requireNamedValue(Enum value, const std::string& source, const std::string& what) {
    if (!isNamedValue(value))
        throw Error(source, 0, what + " " + std::to_string(static_cast<long long>(value)) + " is not one of its values (" + nameList<Enum>() + ")");
}

// The warning for an old spelling: "'anchor' is deprecated: write 'anchors'".
inline std::string deprecationWarning(std::string_view oldName, std::string_view replacement) {
    return "'" + std::string(oldName) + "' is deprecated: write '" + std::string(replacement) + "'";
}

}  // namespace flexfit
