// Internal to src/io: line-by-line reading of text mesh formats (.tri, OBJ, OFF, PLY), with line numbers
// for every error.
#pragma once

#include "flexfit/core.hpp"

#include <charconv>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

namespace flexfit::detail {

struct TextLine {
    std::size_t number = 0;
    std::vector<std::string_view> tokens;
};

inline bool isBlank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

inline std::vector<std::string_view> tokenize(std::string_view line) {
    std::vector<std::string_view> tokens;
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && isBlank(line[i])) ++i;
        const std::size_t start = i;
        while (i < line.size() && !isBlank(line[i])) ++i;
        if (i > start) tokens.push_back(line.substr(start, i - start));
    }
    return tokens;
}

// The text without a UTF-8 byte order mark in front (editors on Windows write one).
inline std::string_view withoutByteOrderMark(std::string_view text) {
    return text.substr(0, 3) == "\xEF\xBB\xBF" ? text.substr(3) : text;
}

// Walks the text line by line, skipping blank lines, remembering line numbers. A line ends at
// '\n', at "\r\n" or at a '\r' alone (classic Mac OS files; a stray one in a file edited on
// several systems), each counted as one line.
class LineCursor {
public:
    explicit LineCursor(std::string_view text) : text_(withoutByteOrderMark(text)), markLength_(text.size() - text_.size()) {}

    // The raw first line (a .tri model's name), without its end of line.
    std::string_view firstLine() {
        pos_ = 0;
        lineNumber_ = 1;
        return nextRaw();
    }

    // Next non-blank line; false at the end of the text.
    bool next(TextLine& out) {
        while (pos_ < text_.size()) {
            const std::string_view raw = nextRaw();
            ++lineNumber_;
            out.number = lineNumber_;
            out.tokens = tokenize(raw);
            if (!out.tokens.empty()) return true;
        }
        return false;
    }

    std::size_t lineNumber() const { return lineNumber_; }
    // Where the next line starts, in the text as given (a byte order mark counted).
    std::size_t offset() const { return markLength_ + std::min(pos_, text_.size()); }

private:
    // The line at pos_, without its end; pos_ moved past the end.
    std::string_view nextRaw() {
        const std::size_t end = std::min(text_.find_first_of("\r\n", pos_), text_.size());
        const std::string_view line = text_.substr(pos_, end - pos_);
        pos_ = end + (text_.substr(end, 2) == "\r\n" ? 2 : 1);
        return line;
    }

    std::string_view text_;
    std::size_t markLength_ = 0;
    std::size_t pos_ = 0;
    std::size_t lineNumber_ = 0;
};

// The line's tokens up to a `#` (the comment it starts, to the end of the line, dropped).
inline void cutComment(TextLine& line) {
    for (std::size_t i = 0; i < line.tokens.size(); ++i) {
        const std::size_t hash = line.tokens[i].find('#');
        if (hash == std::string_view::npos) continue;
        line.tokens[i] = line.tokens[i].substr(0, hash);
        line.tokens.resize(line.tokens[i].empty() ? i : i + 1);
        return;
    }
}

// A token for an error message: at most 40 characters, control bytes as '?'.
inline std::string quoted(std::string_view token) {
    constexpr std::size_t kMax = 40;
    std::string text(token.substr(0, kMax));
    for (char& c : text)
        if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
    return "'" + text + (token.size() > kMax ? "...'" : "'");
}

// A decimal number; a leading '+' is allowed (from_chars alone refuses it).
inline double parseCoordinate(std::string_view token, const std::string& source, std::size_t line) {
    double value = 0.0;
    const std::string_view digits = token.size() > 1 && token[0] == '+' && token[1] != '-' ? token.substr(1) : token;
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (ec == std::errc::result_out_of_range)
        throw InputError(source, line, "coordinate " + quoted(token) + " is out of the range of a double");
    if (ec != std::errc() || end != digits.data() + digits.size())
        throw InputError(source, line, "coordinate " + quoted(token) + " is not a number");
    return value;
}

// Code point c (at most 0x10FFFF) appended to `out` in UTF-8.
inline void appendUtf8(std::string& out, char32_t c) {
    if (c < 0x80) {
        out += char(c);
    } else if (c < 0x800) {
        out += char(0xC0 | (c >> 6));
        out += char(0x80 | (c & 0x3F));
    } else if (c < 0x10000) {
        out += char(0xE0 | (c >> 12));
        out += char(0x80 | ((c >> 6) & 0x3F));
        out += char(0x80 | (c & 0x3F));
    } else {
        out += char(0xF0 | (c >> 18));
        out += char(0x80 | ((c >> 12) & 0x3F));
        out += char(0x80 | ((c >> 6) & 0x3F));
        out += char(0x80 | (c & 0x3F));
    }
}

// UTF-16 `units` (the bytes after the byte order mark) as UTF-8: the same lines, so the readers'
// line numbers stay the file's. Text cut short (an odd number of bytes) or an unpaired
// surrogate is an InputError of `source`, with the line it is on.
inline std::string utf8FromUtf16(std::string_view units, bool bigEndian, const std::string& source) {
    if (units.size() % 2 != 0) throw InputError(source, 0, "UTF-16 text cut short: an odd number of bytes");
    const auto unitAt = [&](std::size_t i) {
        const auto high = static_cast<unsigned char>(units[bigEndian ? i : i + 1]);
        const auto low = static_cast<unsigned char>(units[bigEndian ? i + 1 : i]);
        return char32_t(high << 8 | low);
    };
    std::string out;
    out.reserve(units.size() / 2);
    std::size_t line = 1;  // counted as LineCursor counts: "\r\n", '\n' or '\r' ends one
    char32_t previous = 0;
    for (std::size_t i = 0; i < units.size(); i += 2) {
        char32_t c = unitAt(i);
        if (c >= 0xDC00 && c <= 0xDFFF) throw InputError(source, line, "invalid UTF-16: a low surrogate with no high one before it");
        if (c >= 0xD800 && c <= 0xDBFF) {
            const char32_t low = i + 2 < units.size() ? unitAt(i + 2) : 0;
            if (!(low >= 0xDC00 && low <= 0xDFFF)) throw InputError(source, line, "invalid UTF-16: a high surrogate with no low one after it");
            c = 0x10000 + ((c - 0xD800) << 10) + (low - 0xDC00);
            i += 2;
        }
        line += c == U'\r' || (c == U'\n' && previous != U'\r') ? 1 : 0;
        previous = c;
        appendUtf8(out, c);
    }
    return out;
}

// A text file's bytes as the readers take them: UTF-16 with its byte order mark (Windows tools
// write it: PowerShell's redirection, Notepad's "Unicode") turned into UTF-8, anything else as
// it is (a UTF-8 mark is LineCursor's to skip). UTF-32 is refused.
inline std::string decodedText(std::string bytes, const std::string& source) {
    const std::string_view b = bytes;
    if (b.substr(0, 4) == std::string_view("\x00\x00\xFE\xFF", 4) || b.substr(0, 4) == std::string_view("\xFF\xFE\x00\x00", 4))
        throw InputError(source, 0, "UTF-32 text (its byte order mark) is not read: save the file as UTF-8 or ASCII");
    if (b.substr(0, 2) == "\xFE\xFF") return utf8FromUtf16(b.substr(2), true, source);
    if (b.substr(0, 2) == "\xFF\xFE") return utf8FromUtf16(b.substr(2), false, source);
    return bytes;
}

// The whole file as text; InputError naming it when it is missing, not a file, or unreadable
// ("cannot open the <what> for reading", `what` naming the kind of file).
inline std::string readTextFile(const std::filesystem::path& path, const char* what = "file") {
    std::error_code ec;
    const std::string cannotOpen = std::string("cannot open the ") + what + " for reading";
    if (!std::filesystem::is_regular_file(path, ec))
        throw InputError(path.string(), 0, std::filesystem::exists(path, ec) ? "not a regular file" : cannotOpen + ": it does not exist");
    std::ifstream file(path, std::ios::binary);
    if (!file) throw InputError(path.string(), 0, cannotOpen);
    std::ostringstream buffer;
    buffer << file.rdbuf();
    return buffer.str();
}

// A text format's file (mesh, scene, sweep) as its reader parses it: readTextFile's bytes,
// UTF-16 decoded (decodedText).
inline std::string readTextDocument(const std::filesystem::path& path, const char* what = "file") {
    return decodedText(readTextFile(path, what), path.string());
}

}  // namespace flexfit::detail
