// Sweep files (sweep.hpp): the base scene's TOML document, each run's values set in a copy.
#include "flexfit/sweep.hpp"

#include "core/fnv1a.hpp"
#include "io/scene_document.hpp"
#include "io/text_lines.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>

namespace flexfit {

using NodePtr = std::unique_ptr<toml::node>;

namespace detail {
struct SweepDocument {
    std::string sceneText;  // the base scene, parsed again for each run (a copied toml++ node loses its lines)
    std::vector<std::pair<std::string, NodePtr>> set;       // values every run shares, by dotted key
    std::vector<std::size_t> setLines;
    std::vector<std::vector<std::vector<NodePtr>>> values;  // [parameter][case][key]
};
}  // namespace detail

namespace {

using detail::SweepDocument;

toml::table parseText(const std::string& text, const std::filesystem::path& file) {
    try {
        return toml::parse(text, file.string());
    } catch (const toml::parse_error& e) {
        throw InputError(file.string(), e.source().begin.line, "TOML syntax: " + std::string(e.description()));
    }
}

using detail::lineOf;

NodePtr clone(const toml::node& node) {
    return node.visit([](const auto& x) { return NodePtr(new std::decay_t<decltype(x)>(x)); });
}

std::string tomlText(const toml::node& node) {
    std::ostringstream out;
    node.visit([&](const auto& v) { out << v; });
    return out.str();
}

// The `set` table's values by dotted key: quoted keys ("world.duration" = 1) and TOML's own
// dotted keys or [set.world] sub-tables alike; an inline table is a value.
void flattenSet(const toml::table& t, const std::string& prefix, SweepDocument& d) {
    for (const auto& [key, value] : t) {
        const std::string path = prefix + std::string(key.str());
        if (const toml::table* sub = value.as_table(); sub && !sub->is_inline()) {
            flattenSet(*sub, path + ".", d);
            continue;
        }
        d.set.emplace_back(path, clone(value));
        d.setLines.push_back(lineOf(value));
    }
}

// The parsed [[parameter]] with its cases' values (one node per key).
struct ParsedParameter {
    SweepParameter parameter;
    std::vector<std::vector<NodePtr>> cases;
    std::vector<std::string> valueTexts;  // canonical text of each case, for the run ids
};

std::vector<std::string> keysOf(const toml::table& t, const std::string& file, const std::string& what) {
    const toml::node* key = t.get("key");
    if (!key) throw InputError(file, lineOf(t), what + ": missing 'key'");
    std::vector<std::string> keys;
    if (const auto* s = key->as_string()) keys.push_back(s->get());
    else if (const auto* a = key->as_array()) {
        for (const toml::node& k : *a) {
            if (!k.is_string()) throw InputError(file, lineOf(k), what + ": 'key' must be a string or an array of strings");
            keys.push_back(*k.value<std::string>());
        }
    }
    if (keys.empty()) throw InputError(file, lineOf(*key), what + ": 'key' must be a string or a non-empty array of strings");
    return keys;
}

std::vector<NodePtr> rangeValues(const toml::table& range, const std::string& file, const std::string& what) {
    for (const auto& [k, v] : range)
        if (k != "start" && k != "stop" && k != "count") throw InputError(file, lineOf(v), what + ": unknown range key '" + std::string(k.str()) + "'");
    const auto start = range["start"].value<double>(), stop = range["stop"].value<double>();
    const auto count = range["count"].value<std::int64_t>();
    if (!start || !stop || !count || !std::isfinite(*start) || !std::isfinite(*stop))
        throw InputError(file, lineOf(range), what + ": 'range' needs finite numbers start and stop and an integer count");
    if (*count < 1 || *count > 100000) throw InputError(file, lineOf(range), what + ": range count must be 1 to 100000");
    std::vector<NodePtr> values;
    for (std::int64_t i = 0; i < *count; ++i) {
        const double v = *count == 1 ? *start : *start + (*stop - *start) * double(i) / double(*count - 1);
        values.push_back(NodePtr(new toml::value<double>(v)));
    }
    return values;
}

ParsedParameter readParameter(const toml::table& t, const std::string& file, std::size_t index) {
    ParsedParameter p;
    const std::string what = "parameter " + std::to_string(index + 1);
    p.parameter.line = lineOf(t);
    for (const auto& [k, v] : t)
        if (k != "name" && k != "key" && k != "values" && k != "range" && k != "labels")
            throw InputError(file, lineOf(v), what + ": unknown key '" + std::string(k.str()) + "'");
    const auto name = t["name"].value<std::string>();
    if (!name || name->empty()) throw InputError(file, p.parameter.line, what + ": missing 'name' (a non-empty string)");
    p.parameter.name = *name;
    const std::string named = "parameter '" + *name + "'";
    p.parameter.keys = keysOf(t, file, named);
    const toml::array* values = t["values"].as_array();
    const toml::table* range = t["range"].as_table();
    if (bool(values) == bool(range)) throw InputError(file, p.parameter.line, named + ": give either 'values' (an array) or 'range' (a table)");
    std::vector<NodePtr> cases;
    if (values) {
        for (const toml::node& v : *values) cases.push_back(clone(v));
        if (cases.empty()) throw InputError(file, lineOf(*values), named + ": 'values' is empty");
    } else {
        if (p.parameter.keys.size() != 1) throw InputError(file, lineOf(*range), named + ": a range sets one key");
        cases = rangeValues(*range, file, named);
    }
    for (NodePtr& c : cases) {
        p.valueTexts.push_back(tomlText(*c));
        std::vector<NodePtr> perKey;
        if (p.parameter.keys.size() == 1) {
            perKey.push_back(std::move(c));
        } else {
            const toml::array* tuple = c->as_array();
            if (!tuple || tuple->size() != p.parameter.keys.size())
                throw InputError(file, p.parameter.line,
                                 named + ": with " + std::to_string(p.parameter.keys.size()) + " keys each value is an array of as many (one per key): " +
                                     p.valueTexts.back());
            for (const toml::node& v : *tuple) perKey.push_back(clone(v));
        }
        p.cases.push_back(std::move(perKey));
    }
    if (const toml::array* labels = t["labels"].as_array()) {
        if (labels->size() != p.cases.size())
            throw InputError(file, lineOf(*labels), named + ": " + std::to_string(labels->size()) + " labels for " + std::to_string(p.cases.size()) + " values");
        for (const toml::node& l : *labels) {
            if (!l.is_string()) throw InputError(file, lineOf(l), named + ": labels must be strings");
            p.parameter.labels.push_back(*l.value<std::string>());
        }
    } else if (t.contains("labels")) {
        throw InputError(file, lineOf(*t.get("labels")), named + ": 'labels' must be an array of strings");
    } else {
        for (std::size_t c = 0; c < p.cases.size(); ++c) {  // strings as they read, other values as TOML
            const toml::node& first = *p.cases[c].front();
            p.parameter.labels.push_back(p.parameter.keys.size() == 1 && first.is_string() ? *first.value<std::string>() : p.valueTexts[c]);
        }
    }
    std::set<std::string> seen;
    for (const std::string& v : p.valueTexts)
        if (!seen.insert(v).second) throw InputError(file, p.parameter.line, named + ": the value " + v + " is listed twice");
    return p;
}

// Sets `value` at the dotted `key` of `scene`: tables by key, arrays of tables by a part's
// name (the table whose "name" is the segment) or by index, arrays by index.
void setKey(toml::table& scene, const std::string& key, const toml::node& value) {
    std::vector<std::string> path;
    std::string segment;
    for (std::istringstream in(key); std::getline(in, segment, '.');) path.push_back(segment);
    if (path.empty() || std::find(path.begin(), path.end(), "") != path.end()) throw std::invalid_argument("'" + key + "' is not a dotted key");
    toml::node* at = &scene;
    for (std::size_t i = 0; i < path.size(); ++i) {
        const std::string& s = path[i];
        const bool last = i + 1 == path.size();
        if (toml::table* t = at->as_table()) {
            if (last) {
                value.visit([&](const auto& x) { t->insert_or_assign(s, x); });
                return;
            }
            at = t->get(s);
            if (!at) throw std::invalid_argument("the base scene has no '" + s + "' in '" + key + "'");
        } else if (toml::array* a = at->as_array()) {
            std::size_t index = a->size();
            if (std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; })) {
                index = s.size() < 10 ? std::size_t(std::stoull(s)) : a->size();
            } else {
                for (std::size_t j = 0; j < a->size(); ++j)
                    if (const toml::table* e = a->get(j)->as_table(); e && (*e)["name"].value<std::string>() == s) index = j;
            }
            if (index >= a->size()) throw std::invalid_argument("no element '" + s + "' in the array of '" + key + "'");
            if (last) {
                value.visit([&](const auto& x) { a->replace(a->cbegin() + std::ptrdiff_t(index), x); });
                return;
            }
            at = a->get(index);
        } else {
            throw std::invalid_argument("'" + s + "' in '" + key + "' is below a value, not a table or an array");
        }
    }
}

// What every run's results depend on besides its values: the base scene's text, the shared
// values, the duration, each parameter's keys. A run's id mixes it in, so editing any of them
// makes every run new (finished runs of the old sweep are not reused).
std::uint64_t sweepFingerprint(const SweepDocument& d, const std::optional<double>& duration, const std::vector<ParsedParameter>& parameters) {
    detail::Fnv1a h;
    h.mix(d.sceneText.data(), d.sceneText.size() + 1);
    for (const auto& [key, value] : d.set) {
        const std::string text = key + "=" + tomlText(*value);
        h.mix(text.data(), text.size() + 1);
    }
    if (duration) h.mix(&*duration, sizeof(double));
    for (const ParsedParameter& p : parameters)
        for (const std::string& k : p.parameter.keys) h.mix(k.data(), k.size() + 1);
    return h.value();
}

std::string runId(std::uint64_t fingerprint, const std::vector<ParsedParameter>& parameters, const std::vector<std::size_t>& cases) {
    detail::Fnv1a h;
    h.mix(&fingerprint, sizeof fingerprint);
    for (std::size_t p = 0; p < parameters.size(); ++p) {
        const std::string& name = parameters[p].parameter.name;
        const std::string& value = parameters[p].valueTexts[cases[p]];
        h.mix(name.data(), name.size() + 1);  // with the terminating zero: names and values cannot run together
        h.mix(value.data(), value.size() + 1);
    }
    char id[17];
    std::snprintf(id, sizeof id, "%016llx", static_cast<unsigned long long>(h.value()));
    return id;
}

toml::table runDocument(const Sweep& sweep, std::size_t run) {
    const SweepDocument& d = *sweep.document;
    toml::table scene = parseText(d.sceneText, sweep.scene);
    for (std::size_t i = 0; i < d.set.size(); ++i) {
        try {
            setKey(scene, d.set[i].first, *d.set[i].second);
        } catch (const std::invalid_argument& e) {
            throw InputError(sweep.file.string(), d.setLines[i], std::string("set: ") + e.what());
        }
    }
    for (std::size_t p = 0; p < sweep.parameters.size(); ++p) {
        const auto& values = d.values[p][sweep.runs[run].cases[p]];
        for (std::size_t k = 0; k < values.size(); ++k) {
            try {
                setKey(scene, sweep.parameters[p].keys[k], *values[k]);
            } catch (const std::invalid_argument& e) {
                throw InputError(sweep.file.string(), sweep.parameters[p].line, "parameter '" + sweep.parameters[p].name + "': " + e.what());
            }
        }
    }
    return scene;
}

// The line of the parameter a problem with a value set by the sweep is most likely about: the
// one whose key's last segment the problem quotes, else the first.
std::size_t lineOfValue(const Sweep& sweep, const std::string& problem) {
    for (const SweepParameter& p : sweep.parameters)
        for (const std::string& key : p.keys)
            if (problem.find("'" + key.substr(key.rfind('.') + 1) + "'") != std::string::npos) return p.line;
    return sweep.parameters.empty() ? 1 : sweep.parameters.front().line;
}

}  // namespace

std::vector<std::string> Sweep::labels(std::size_t run) const {
    std::vector<std::string> out;
    for (std::size_t p = 0; p < parameters.size(); ++p) out.push_back(parameters[p].labels[runs.at(run).cases[p]]);
    return out;
}

Scene sweepScene(const Sweep& sweep, std::size_t run) {
    if (run >= sweep.runs.size()) throw InputError(sweep.file.string(), 0, "no run " + std::to_string(run) + " (the sweep has " + std::to_string(sweep.runs.size()) + ")");
    const toml::table document = runDocument(sweep, run);
    const std::string source = sweep.file.string() + " run " + sweep.runs[run].id;
    std::string values;
    for (std::size_t p = 0; p < sweep.parameters.size(); ++p)
        values += (p ? ", " : "") + sweep.parameters[p].name + " = " + sweep.parameters[p].labels[sweep.runs[run].cases[p]];
    const auto inRun = [&](const std::string& problem) { return "run " + sweep.runs[run].id + " (" + values + "): " + problem; };
    Scene scene;
    try {
        scene = detail::readSceneDocument(document, source, sweep.scene.parent_path(), sweep.read);
    } catch (const InputError& e) {
        // The problem is in a value the sweep set (line 0) or in the base scene (its line).
        if (e.line() == 0) throw InputError(sweep.file.string(), lineOfValue(sweep, e.problem()), inRun(e.problem()));
        throw InputError(sweep.scene.string(), e.line(), e.problem() + " (in run " + sweep.runs[run].id + " of " + sweep.file.string() + ": " + values + ")");
    }
    if (sweep.duration) scene.duration = *sweep.duration;
    scene.linesFile = sweep.scene.string();
    if (const std::optional<std::string> problem = stepCountProblem(scene.duration, scene.world.timeStep))
        throw InputError(sweep.file.string(), lineOfValue(sweep, "'time_step'"), inRun(*problem));
    return scene;
}

Sweep loadSweep(const std::filesystem::path& file, bool checkRuns, const SceneReadOptions& read) {
    const std::string name = file.string();
    const toml::table root = parseText(detail::readTextDocument(file, "sweep file"), file);
    for (const auto& [k, v] : root)
        if (k != "scene" && k != "duration" && k != "set" && k != "parameter") throw InputError(name, lineOf(v), "unknown key '" + std::string(k.str()) + "'");
    Sweep sweep;
    sweep.file = file;
    sweep.read = read;
    const auto scene = root["scene"].value<std::string>();
    if (!scene) throw InputError(name, 1, "missing 'scene' (the base scene file, relative to the sweep file)");
    sweep.scene = file.parent_path() / *scene;
    if (root.contains("duration")) {
        const auto d = root["duration"].value<double>();
        if (!d || !(*d > 0.0) || !std::isfinite(*d)) throw InputError(name, lineOf(*root.get("duration")), "'duration' must be a positive number of seconds");
        sweep.duration = d;
    }
    auto document = std::make_shared<SweepDocument>();
    document->sceneText = detail::readTextDocument(sweep.scene, "base scene file");
    (void)parseText(document->sceneText, sweep.scene);  // its syntax errors name its own lines
    if (const toml::node* set = root.get("set")) {
        const toml::table* t = set->as_table();
        if (!t) throw InputError(name, lineOf(*set), "'set' must be a table of \"dotted.key\" = value");
        flattenSet(*t, "", *document);
    }
    std::vector<ParsedParameter> parsed;
    if (const toml::node* list = root.get("parameter")) {
        const toml::array* a = list->as_array();
        if (!a || !a->is_array_of_tables()) throw InputError(name, lineOf(*list), "'parameter' must be an array of tables ([[parameter]])");
        std::set<std::string> names;
        for (std::size_t i = 0; i < a->size(); ++i) {
            parsed.push_back(readParameter(*a->get(i)->as_table(), name, i));
            if (!names.insert(parsed.back().parameter.name).second)
                throw InputError(name, parsed.back().parameter.line, "parameter name '" + parsed.back().parameter.name + "' used twice");
        }
    }
    // The runs: the product, the first parameter slowest.
    const std::uint64_t fingerprint = sweepFingerprint(*document, sweep.duration, parsed);
    std::vector<std::size_t> cases(parsed.size(), 0);
    for (;;) {
        sweep.runs.push_back({runId(fingerprint, parsed, cases), cases});
        std::size_t p = parsed.size();
        while (p > 0 && ++cases[p - 1] == parsed[p - 1].cases.size()) cases[--p] = 0;
        if (p == 0) break;
        if (sweep.runs.size() >= 1000000) throw InputError(name, 0, "more than a million runs");
    }
    for (ParsedParameter& p : parsed) {
        sweep.parameters.push_back(std::move(p.parameter));
        document->values.push_back(std::move(p.cases));
    }
    sweep.document = std::move(document);
    if (!checkRuns) return sweep;
    // Every run checked before any runs, and every run with the same parts (the table's columns).
    std::vector<std::string> parts;
    for (std::size_t r = 0; r < sweep.runs.size(); ++r) {
        const Scene runScene = sweepScene(sweep, r);
        for (const SceneWarning& w : runScene.warnings)
            if (std::none_of(sweep.warnings.begin(), sweep.warnings.end(),
                             [&](const SceneWarning& seen) { return seen.line == w.line && seen.message == w.message; }))
                sweep.warnings.push_back(w);
        std::vector<std::string> names;
        for (const ScenePart& p : runScene.parts) names.push_back(p.name);
        if (r == 0) parts = names;
        else if (names != parts) throw InputError(name, sweep.parameters.front().line, "run " + sweep.runs[r].id + " has other parts than the first run (a parameter renames or adds parts)");
    }
    return sweep;
}

}  // namespace flexfit
