// PNG files through libpng: RGBA8 images, rows top to bottom.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

namespace flexfit::viewer {

struct Image {
    int width = 0, height = 0;
    std::vector<std::uint8_t> rgba;  // width * height * 4, top row first
    const std::uint8_t* pixel(int x, int y) const { return &rgba[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * 4]; }
};

// Throws std::runtime_error naming the file when it cannot be written or read.
void writePng(const std::filesystem::path& file, const Image& image);
Image readPng(const std::filesystem::path& file);

}  // namespace flexfit::viewer
