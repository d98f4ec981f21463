// Sweep files (sweep.hpp): the base scene's TOML document, each run's values set in a copy.
#include "flexfit/sweep.hpp"

#include "core/fnv1a.hpp"
#include "io/scene_document.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>

namespace flexfit {

using NodePtr = std::unique_ptr<toml::node>;

namespace detail {
struct SweepDocument {
    toml::table scene;                                  // the base scene
    std::vector<std::vector<std::vector<NodePtr>>> values;  // [parameter][case][key]
};
}  // namespace detail

namespace {

using detail::SweepDocument;

toml::table parseFile(const std::filesystem::path& file, const char* what) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw InputError(file.string(), 0, std::string("cannot open the ") + what);
    std::ostringstream text;
    text << in.rdbuf();
    try {
        return toml::parse(text.str(), file.string());
    } catch (const toml::parse_error& e) {
        throw InputError(file.string(), e.source().begin.line, "TOML syntax: " + std::string(e.description()));
    }
}

std::size_t lineOf(const toml::node& node) { return node.source().begin.line; }

NodePtr clone(const toml::node& node) {
    return node.visit([](const auto& x) { return NodePtr(new std::decay_t<decltype(x)>(x)); });
}

std::string tomlText(const toml::node& node) {
    std::ostringstream out;
    node.visit([&](const auto& v) { out << v; });
    return out.str();
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

std::string runId(const std::vector<ParsedParameter>& parameters, const std::vector<std::size_t>& cases) {
    detail::Fnv1a h;
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
    toml::table scene = sweep.document->scene;
    for (std::size_t p = 0; p < sweep.parameters.size(); ++p) {
        const auto& values = sweep.document->values[p][sweep.runs[run].cases[p]];
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
    Scene scene;
    try {
        scene = detail::readSceneDocument(document, source, sweep.scene.parent_path(), {});
    } catch (const InputError& e) {
        // The problem is in a value the sweep set (line 0) or in the base scene (its line).
        std::string values;
        for (std::size_t p = 0; p < sweep.parameters.size(); ++p)
            values += (p ? ", " : "") + sweep.parameters[p].name + " = " + sweep.parameters[p].labels[sweep.runs[run].cases[p]];
        if (e.line() == 0) throw InputError(sweep.file.string(), lineOfValue(sweep, e.problem()), "run " + sweep.runs[run].id + " (" + values + "): " + e.problem());
        throw InputError(sweep.scene.string(), e.line(), e.problem() + " (in run " + sweep.runs[run].id + " of " + sweep.file.string() + ": " + values + ")");
    }
    if (sweep.duration) scene.duration = *sweep.duration;
    return scene;
}

Sweep loadSweep(const std::filesystem::path& file) {
    const std::string name = file.string();
    const toml::table root = parseFile(file, "sweep file");
    for (const auto& [k, v] : root)
        if (k != "scene" && k != "duration" && k != "set" && k != "parameter") throw InputError(name, lineOf(v), "unknown key '" + std::string(k.str()) + "'");
    Sweep sweep;
    sweep.file = file;
    const auto scene = root["scene"].value<std::string>();
    if (!scene) throw InputError(name, 1, "missing 'scene' (the base scene file, relative to the sweep file)");
    sweep.scene = file.parent_path() / *scene;
    if (root.contains("duration")) {
        const auto d = root["duration"].value<double>();
        if (!d || !(*d > 0.0) || !std::isfinite(*d)) throw InputError(name, lineOf(*root.get("duration")), "'duration' must be a positive number of seconds");
        sweep.duration = d;
    }
    auto document = std::make_shared<SweepDocument>();
    document->scene = parseFile(sweep.scene, "base scene file");
    // Values every run shares: set once in the base.
    if (const toml::node* set = root.get("set")) {
        const toml::table* t = set->as_table();
        if (!t) throw InputError(name, lineOf(*set), "'set' must be a table of \"dotted.key\" = value");
        for (const auto& [key, value] : *t) {
            try {
                setKey(document->scene, std::string(key.str()), value);
            } catch (const std::invalid_argument& e) {
                throw InputError(name, lineOf(value), std::string("set: ") + e.what());
            }
        }
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
    std::vector<std::size_t> cases(parsed.size(), 0);
    for (;;) {
        sweep.runs.push_back({runId(parsed, cases), cases});
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
    for (std::size_t r = 0; r < sweep.runs.size(); ++r) (void)sweepScene(sweep, r);  // every run checked before any runs
    return sweep;
}

}  // namespace flexfit
