// The PLY reader: the file's own vertex order, coordinates as the file stores them (a double
// property stays a double), and the place of every problem: its line in ASCII files, the
// element and its byte offset in binary ones. (assimp's PLY importer gives one vertex per face
// corner welded back in first-use order, in single precision: a scan's vertex 574 would not be
// mass 574.)
//
// Read: `format ascii 1.0`, `binary_little_endian 1.0` and `binary_big_endian 1.0`; every
// element the header declares, in its order, with properties of any of the eight scalar types
// (`char`..`double` and their `int8`..`float64` names) and lists. The `vertex` element's x, y
// and z give the vertices; the `face` element's `vertex_indices` (or `vertex_index`) list the
// polygons, triangulated as in OBJ; a `tristrips` element's `vertex_indices` lists triangle
// strips (as scanners of the Stanford repository's era wrote them), -1 ending a strip: triangle
// k of a strip is (s_k, s_k+1, s_k+2), every other one turned to keep the strip's winding, and
// those with a repeated corner (how strips join and turn) are part of the encoding, not faces.
// Other elements and properties (colours, normals, texture coordinates, edges, materials) are
// read past. ASCII files hold one element per line.
// Header lines that are not PLY are read past with a warning (Blender 2.4 wrote one). Lines end
// at \n, \r\n or a lone \r (text_lines.hpp), in the header as in an ASCII body; binary data
// after a lone \r is refused (its first byte could be a \n).
// Refused, each with its place: a missing `ply` line, an unknown format or type, a header
// without `end_header`, no x/y/z, no faces (point clouds), a face of fewer than 3 corners or with
// an index out of range, a value that is not a number of its type, a file that ends early or
// goes on after its last element.
#include "flexfit/mesh_io.hpp"
#include "io_internal.hpp"
#include "polygons.hpp"
#include "text_lines.hpp"

#include <bit>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>

namespace flexfit {
namespace {

using detail::quoted;

enum class PlyType : std::uint8_t { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

std::optional<PlyType> typeNamed(std::string_view name) {
    static constexpr std::pair<std::string_view, PlyType> kNames[] = {
        {"char", PlyType::Int8},    {"int8", PlyType::Int8},       {"uchar", PlyType::UInt8},    {"uint8", PlyType::UInt8},
        {"short", PlyType::Int16},  {"int16", PlyType::Int16},     {"ushort", PlyType::UInt16},  {"uint16", PlyType::UInt16},
        {"int", PlyType::Int32},    {"int32", PlyType::Int32},     {"uint", PlyType::UInt32},    {"uint32", PlyType::UInt32},
        {"float", PlyType::Float32}, {"float32", PlyType::Float32}, {"double", PlyType::Float64}, {"float64", PlyType::Float64}};
    for (const auto& [text, type] : kNames)
        if (text == name) return type;
    return std::nullopt;
}

std::size_t sizeOf(PlyType t) {
    switch (t) {
        case PlyType::Int8:
        case PlyType::UInt8: return 1;
        case PlyType::Int16:
        case PlyType::UInt16: return 2;
        case PlyType::Int32:
        case PlyType::UInt32:
        case PlyType::Float32: return 4;
        case PlyType::Float64: return 8;
    }
    return 0;
}

bool isFloating(PlyType t) { return t == PlyType::Float32 || t == PlyType::Float64; }

struct PlyProperty {
    std::string name;
    PlyType type = PlyType::Float32;  // a list's items
    std::optional<PlyType> countType;  // set for a list
};

struct PlyElement {
    std::string name;
    std::int64_t count = 0;
    std::vector<PlyProperty> properties;
    // Where the vertex coordinates and the face list are, when this is that element.
    int x = -1, y = -1, z = -1, corners = -1;
};

enum class PlyFormat { Ascii, LittleEndian, BigEndian };

struct PlyHeader {
    PlyFormat format = PlyFormat::Ascii;
    std::vector<PlyElement> elements;
    std::size_t bodyOffset = 0;  // first byte after end_header's line
    std::size_t lines = 0;       // lines the header takes
    std::vector<std::string> warnings;
};

int propertyIndex(const PlyElement& e, std::initializer_list<std::string_view> names) {
    for (std::size_t i = 0; i < e.properties.size(); ++i)
        for (std::string_view n : names)
            if (e.properties[i].name == n) return int(i);
    return -1;
}

PlyType typeOf(std::string_view token, const std::string& source, std::size_t line) {
    const std::optional<PlyType> t = typeNamed(token);
    if (!t) throw InputError(source, line, "unknown property type " + quoted(token));
    return *t;
}

PlyHeader readHeader(std::string_view text, const std::string& source) {
    PlyHeader header;
    if (detail::withoutByteOrderMark(text).empty()) throw InputError(source, 0, "the header has no end_header line: the file is empty");
    detail::LineCursor cursor(text);  // any line end, as the ASCII body: \n, \r\n or a lone \r
    if (detail::tokenize(cursor.firstLine()) != std::vector<std::string_view>{"ply"})
        throw InputError(source, 1, "not a PLY file: the first line is not 'ply'");
    const bool loneCarriageReturns = text[cursor.offset() - 1] == '\r';  // how the first line ended
    bool formatSeen = false;
    std::size_t line = 1;
    detail::TextLine next;
    while (true) {
        if (!cursor.next(next)) throw InputError(source, cursor.lineNumber(), "the header has no end_header line");
        line = next.number;
        const std::vector<std::string_view>& tokens = next.tokens;
        if (tokens[0] == "comment" || tokens[0] == "obj_info") continue;
        const std::string_view keyword = tokens[0];
        if (keyword == "end_header") break;
        if (keyword == "format") {
            if (tokens.size() != 3) throw InputError(source, line, "a format line is 'format <ascii|binary_little_endian|binary_big_endian> 1.0'");
            if (tokens[1] == "ascii") header.format = PlyFormat::Ascii;
            else if (tokens[1] == "binary_little_endian") header.format = PlyFormat::LittleEndian;
            else if (tokens[1] == "binary_big_endian") header.format = PlyFormat::BigEndian;
            else throw InputError(source, line, "unknown format " + quoted(tokens[1]));
            if (tokens[2] != "1.0") throw InputError(source, line, "unknown format version " + quoted(tokens[2]) + " (1.0 is read)");
            formatSeen = true;
        } else if (keyword == "element") {
            std::int64_t count = -1;
            if (tokens.size() == 3) {
                const auto [stop, ec] = std::from_chars(tokens[2].data(), tokens[2].data() + tokens[2].size(), count);
                if (ec != std::errc() || stop != tokens[2].data() + tokens[2].size()) count = -1;
            }
            if (tokens.size() != 3 || count < 0) throw InputError(source, line, "an element line is 'element <name> <count>', the count an integer >= 0");
            header.elements.push_back({std::string(tokens[1]), count, {}});
        } else if (keyword == "property") {
            if (header.elements.empty()) throw InputError(source, line, "a property before any element");
            PlyProperty p;
            if (tokens.size() == 5 && tokens[1] == "list") {
                p.countType = typeOf(tokens[2], source, line);
                p.type = typeOf(tokens[3], source, line);
                if (isFloating(*p.countType)) throw InputError(source, line, "a list's count type must be an integer type");
                p.name = tokens[4];
            } else if (tokens.size() == 3) {
                p.type = typeOf(tokens[1], source, line);
                p.name = tokens[2];
            } else {
                throw InputError(source, line, "a property line is 'property <type> <name>' or 'property list <type> <type> <name>'");
            }
            header.elements.back().properties.push_back(std::move(p));
        } else {  // Blender 2.4 wrote its "Created by ..." without `comment`: read past, as a comment
            header.warnings.push_back("line " + std::to_string(line) + ": header line starting " + quoted(keyword) +
                                      " is not PLY (read as a comment)");
        }
    }
    if (!formatSeen) throw InputError(source, line, "the header has no format line");
    header.bodyOffset = std::min(cursor.offset(), text.size());
    // A binary body's first byte could be taken for the end of end_header's line: "\r\n"
    // (most writers) is read as one end; lone \r line ends before binary data are refused, not
    // guessed (a first data byte 0x0A would look like "\r\n"), whether the first line or the
    // end_header line shows them.
    if (header.format != PlyFormat::Ascii && (loneCarriageReturns || text[header.bodyOffset - 1] == '\r'))
        throw InputError(source, line, "a binary file's header lines must end with \\n or \\r\\n (they end with a lone \\r)");
    header.lines = line;
    return header;
}

// A face or strip element's list of vertex indices, checked.
void locateCorners(PlyElement& e, const std::string& source) {
    e.corners = propertyIndex(e, {"vertex_indices", "vertex_index"});
    if (e.corners < 0 || !e.properties[std::size_t(e.corners)].countType || isFloating(e.properties[std::size_t(e.corners)].type))
        throw InputError(source, 0, "the " + e.name + " element needs a vertex_indices list of integers");
}

// The vertex, face and tristrips elements located, and checked for what the mesh needs.
void locateMesh(PlyHeader& header, const std::string& source) {
    PlyElement* vertex = nullptr;
    PlyElement* face = nullptr;
    PlyElement* strips = nullptr;
    PlyElement* unused = nullptr;
    for (PlyElement& e : header.elements) {
        PlyElement*& slot = e.name == "vertex" ? vertex : e.name == "face" ? face : e.name == "tristrips" ? strips : unused;
        if (&slot != &unused && slot != nullptr) throw InputError(source, 0, "two '" + e.name + "' elements: one of each is read");
        slot = &e;
    }
    if (vertex == nullptr) throw InputError(source, 0, "no vertex element");
    vertex->x = propertyIndex(*vertex, {"x"});
    vertex->y = propertyIndex(*vertex, {"y"});
    vertex->z = propertyIndex(*vertex, {"z"});
    for (int p : {vertex->x, vertex->y, vertex->z})
        if (p < 0 || vertex->properties[std::size_t(p)].countType)
            throw InputError(source, 0, "the vertex element needs x, y and z properties (not lists)");
    if (vertex->count > std::int64_t(std::numeric_limits<Index>::max()))
        throw InputError(source, 0, std::to_string(vertex->count) + " vertices exceed the supported maximum");
    if ((face == nullptr || face->count == 0) && (strips == nullptr || strips->count == 0))
        throw InputError(source, 0, "no faces: a point cloud cannot be simulated");
    for (PlyElement* e : {face, strips})
        if (e != nullptr) locateCorners(*e, source);
}

// What the elements give the mesh, and where each polygon came from.
struct PlyContent {
    TriMesh mesh;
    MeshSourceLines lines;  // ASCII only
    std::size_t fanned = 0;
    std::vector<Index> corners;
};

// One element instance's values, one after another: from an ASCII line's tokens or from bytes.
class ValueSource {
public:
    ValueSource(const PlyHeader& header, std::string_view text, const std::string& source)
        : format_(header.format), text_(text), source_(source), cursor_(text.substr(header.bodyOffset)), headerLines_(header.lines),
          offset_(header.bodyOffset) {}

    // Starts the next instance of `element` (its `index`-th); false when the file has ended.
    bool start(const PlyElement& element, std::int64_t index) {
        element_ = &element;
        index_ = index;
        if (format_ != PlyFormat::Ascii) return offset_ < text_.size();
        if (!cursor_.next(line_)) return false;
        line_.number += headerLines_;
        token_ = 0;
        return true;
    }
    // The instance's ASCII line (0 for binary files).
    std::size_t line() const { return format_ == PlyFormat::Ascii ? line_.number : 0; }

    double number(PlyType t) {
        if (format_ == PlyFormat::Ascii) {
            const std::string_view token = nextToken();
            if (!isFloating(t)) return double(integerToken(token, t));
            return detail::parseCoordinate(token, source_, line());
        }
        const unsigned char* b = bytes(sizeOf(t));
        switch (t) {
            case PlyType::Int8: return double(std::int8_t(b[0]));
            case PlyType::UInt8: return double(b[0]);
            case PlyType::Int16: return double(std::int16_t(load<std::uint16_t>(b)));
            case PlyType::UInt16: return double(load<std::uint16_t>(b));
            case PlyType::Int32: return double(std::int32_t(load<std::uint32_t>(b)));
            case PlyType::UInt32: return double(load<std::uint32_t>(b));
            case PlyType::Float32: return double(std::bit_cast<float>(load<std::uint32_t>(b)));
            case PlyType::Float64: return std::bit_cast<double>(load<std::uint64_t>(b));
        }
        return 0.0;
    }
    std::int64_t integer(PlyType t) {
        if (format_ == PlyFormat::Ascii) return integerToken(nextToken(), t);
        return std::int64_t(number(t));  // an integer type: exact in a double
    }
    // Reads past a value or a list (in ASCII without reading the values: only what is used must
    // be a number of its type).
    void skip(const PlyProperty& p) {
        const std::int64_t n = p.countType ? integer(*p.countType) : 1;
        for (std::int64_t i = 0; i < n; ++i) {
            if (format_ == PlyFormat::Ascii)
                nextToken();
            else
                bytes(sizeOf(p.type));
        }
    }
    // The last line read, for an ASCII file that ends early (0 for binary files).
    std::size_t lastLine() const { return format_ == PlyFormat::Ascii ? cursor_.lineNumber() + headerLines_ : 0; }
    // After an ASCII instance: nothing may be left on its line.
    void finish() {
        if (format_ == PlyFormat::Ascii && token_ < line_.tokens.size())
            fail(std::to_string(line_.tokens.size() - token_) + " values more than its properties hold");
    }
    // After the last element: nothing may be left.
    void requireEnd() {
        if (format_ == PlyFormat::Ascii) {
            if (cursor_.next(line_)) throw InputError(source_, line_.number + headerLines_, "more data after the last element");
        } else if (text_.find_first_not_of(" \t\r\n", offset_) != std::string_view::npos) {  // an end of line is allowed
            throw InputError(source_, 0, std::to_string(text_.size() - offset_) + " bytes after the last element");
        }
    }
    [[noreturn]] void fail(const std::string& problem) const {
        const std::string what = element_->name + " " + std::to_string(index_);
        if (format_ == PlyFormat::Ascii) throw InputError(source_, line(), what + ": " + problem);
        throw InputError(source_, 0, what + " (byte " + std::to_string(offset_) + "): " + problem);
    }

private:
    std::string_view nextToken() {
        if (token_ >= line_.tokens.size()) fail("fewer values than its properties hold");
        return line_.tokens[token_++];
    }
    std::int64_t integerToken(std::string_view token, PlyType t) {
        std::int64_t value = 0;
        const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
        if (ec != std::errc() || end != token.data() + token.size()) fail("value " + quoted(token) + " is not an integer");
        const auto [lowest, highest] = integerRange(t);
        if (value < lowest || value > highest) fail("value " + quoted(token) + " does not fit its type");
        return value;
    }
    static std::pair<std::int64_t, std::int64_t> integerRange(PlyType t) {
        switch (t) {
            case PlyType::Int8: return {-128, 127};
            case PlyType::UInt8: return {0, 255};
            case PlyType::Int16: return {-32768, 32767};
            case PlyType::UInt16: return {0, 65535};
            case PlyType::Int32: return {std::numeric_limits<std::int32_t>::min(), std::numeric_limits<std::int32_t>::max()};
            default: return {0, std::numeric_limits<std::uint32_t>::max()};
        }
    }
    const unsigned char* bytes(std::size_t n) {
        if (text_.size() - offset_ < n) fail("the file ends inside it");
        const auto* b = reinterpret_cast<const unsigned char*>(text_.data() + offset_);
        offset_ += n;
        return b;
    }
    template <class U>
    U load(const unsigned char* b) const {
        U value;
        std::memcpy(&value, b, sizeof(U));
        if ((format_ == PlyFormat::BigEndian) == (std::endian::native == std::endian::big)) return value;
        if constexpr (sizeof(U) == 2) return __builtin_bswap16(value);
        else if constexpr (sizeof(U) == 4) return __builtin_bswap32(value);
        else return __builtin_bswap64(value);
    }

    PlyFormat format_;
    std::string_view text_;
    const std::string& source_;
    detail::LineCursor cursor_;
    std::size_t headerLines_;
    std::size_t offset_;
    detail::TextLine line_;
    std::size_t token_ = 0;
    const PlyElement* element_ = nullptr;
    std::int64_t index_ = 0;
};

void readVertex(const PlyElement& e, ValueSource& in, PlyContent& out) {
    Vec3 p = Vec3::Zero();
    for (std::size_t i = 0; i < e.properties.size(); ++i) {
        const PlyProperty& property = e.properties[i];
        if (int(i) == e.x || int(i) == e.y || int(i) == e.z)
            p[int(i) == e.x ? 0 : int(i) == e.y ? 1 : 2] = in.number(property.type);
        else
            in.skip(property);
    }
    out.mesh.vertices.push_back(p);
    if (in.line() > 0) out.lines.vertexLine.push_back(in.line());
}

// Triangle k of a strip is (s_k, s_k+1, s_k+2), odd ones turned so the strip keeps one winding;
// a triangle with a repeated corner joins or turns the strip and is no face.
void addStrip(const std::vector<Index>& s, std::vector<Face>& faces) {
    for (std::size_t k = 0; k + 2 < s.size(); ++k) {
        const Face f = k % 2 == 0 ? Face{s[k], s[k + 1], s[k + 2]} : Face{s[k + 1], s[k], s[k + 2]};
        if (f[0] != f[1] && f[1] != f[2] && f[0] != f[2]) faces.push_back(f);
    }
}

// An instance of a face or strip element: its other properties read past, its list of vertex
// indices handed to corners(count, property) to read.
template <class Corners>
void readCornerList(const PlyElement& e, ValueSource& in, Corners corners) {
    for (std::size_t i = 0; i < e.properties.size(); ++i) {
        const PlyProperty& property = e.properties[i];
        if (int(i) == e.corners)
            corners(in.integer(*property.countType), property);
        else
            in.skip(property);
    }
}

void readFace(const PlyElement& e, std::int64_t vertexCount, ValueSource& in, PlyContent& out) {
    readCornerList(e, in, [&](std::int64_t n, const PlyProperty& property) {
        if (n < 3) in.fail("a face needs 3 corners, found " + std::to_string(n));
        out.corners.clear();
        for (std::int64_t k = 0; k < n; ++k) {
            const std::int64_t v = in.integer(property.type);
            if (v < 0 || v >= vertexCount)
                in.fail("face corner " + std::to_string(v) + " out of range (the file has " + std::to_string(vertexCount) +
                        " vertices, numbered from 0)");
            out.corners.push_back(Index(v));
        }
    });
    // The corners are checked against the vertex count, but the vertices come first only when
    // the header says so: triangulated once every element is read.
}

// A tristrips instance's strips as triangles (into out.mesh.faces, vertices checked later).
void readStrips(const PlyElement& e, std::int64_t vertexCount, ValueSource& in, PlyContent& out) {
    readCornerList(e, in, [&](std::int64_t n, const PlyProperty& property) {
        std::vector<Index> strip;
        for (std::int64_t k = 0; k <= n; ++k) {
            const std::int64_t v = k < n ? in.integer(property.type) : -1;
            if (v == -1) {
                addStrip(strip, out.mesh.faces);
                strip.clear();
                continue;
            }
            if (v < 0 || v >= vertexCount)
                in.fail("strip corner " + std::to_string(v) + " out of range (the file has " + std::to_string(vertexCount) +
                        " vertices, numbered from 0; -1 ends a strip)");
            strip.push_back(Index(v));
        }
    });
}

}  // namespace

MeshReadResult parsePly(std::string_view text, const std::string& source, const MeshReadOptions& options) {
    PlyHeader header = readHeader(text, source);
    locateMesh(header, source);
    std::int64_t vertexCount = 0;
    for (const PlyElement& e : header.elements)
        if (e.name == "vertex") vertexCount = e.count;
    PlyContent content;
    ValueSource in(header, text, source);
    struct Polygon {
        std::vector<Index> corners;
        std::size_t line;
    };
    std::vector<Polygon> polygons;
    std::vector<std::size_t> stripLines;  // (strip triangles) the line of each, ASCII only
    for (const PlyElement& e : header.elements) {
        if (e.properties.empty()) continue;  // its instances take no bytes, no values
        for (std::int64_t i = 0; i < e.count; ++i) {
            if (!in.start(e, i))
                throw InputError(source, in.lastLine(),
                                 "the file ends after " + std::to_string(i) + " of its " + std::to_string(e.count) + " " + e.name + " elements");
            if (e.name == "vertex") {
                readVertex(e, in, content);
            } else if (e.name == "face") {
                readFace(e, vertexCount, in, content);
                polygons.push_back({content.corners, in.line()});
            } else if (e.name == "tristrips") {
                readStrips(e, vertexCount, in, content);
                if (in.line() > 0) stripLines.resize(content.mesh.faces.size(), in.line());
            } else {
                for (const PlyProperty& p : e.properties) in.skip(p);
            }
            in.finish();
        }
    }
    in.requireEnd();
    // The strips' triangles first (read into the faces), then the polygons'.
    content.lines.faceLine = std::move(stripLines);
    for (const Polygon& polygon : polygons) {
        if (!detail::triangulatePolygon(content.mesh.vertices, polygon.corners, content.mesh.faces)) ++content.fanned;
        if (polygon.line > 0) content.lines.faceLine.resize(content.mesh.faces.size(), polygon.line);
    }
    MeshReadResult result = finishPolygonRead(std::move(content.mesh), source, content.lines, options, content.fanned);
    result.diagnostics.warnings.insert(result.diagnostics.warnings.begin(), header.warnings.begin(), header.warnings.end());
    return result;
}

MeshReadResult readPly(const std::filesystem::path& path, const MeshReadOptions& options) { return readTextMesh(path, options, parsePly); }

}  // namespace flexfit
