#include "png_io.hpp"

#include <png.h>

#include <cstdio>
#include <memory>
#include <stdexcept>

namespace flexfit::viewer {
namespace {

struct FileCloser {
    void operator()(std::FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& what) {
    throw std::runtime_error(file.string() + ": " + what);
}

}  // namespace

void writePng(const std::filesystem::path& file, const Image& image) {
    if (image.width <= 0 || image.height <= 0 || image.rgba.size() != std::size_t(image.width) * std::size_t(image.height) * 4)
        fail(file, "empty or inconsistent image");
    File f(std::fopen(file.c_str(), "wb"));
    if (!f) fail(file, "cannot open for writing");
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png ? png_create_info_struct(png) : nullptr;
    if (!info) {
        png_destroy_write_struct(&png, nullptr);
        fail(file, "libpng could not start");
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        fail(file, "libpng failed while writing");
    }
    png_init_io(png, f.get());
    png_set_IHDR(png, info, png_uint_32(image.width), png_uint_32(image.height), 8, PNG_COLOR_TYPE_RGBA, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    for (int y = 0; y < image.height; ++y) png_write_row(png, image.rgba.data() + std::size_t(y) * std::size_t(image.width) * 4);
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
}

Image readPng(const std::filesystem::path& file) {
    png_image header{};
    header.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&header, file.c_str())) fail(file, std::string("cannot read PNG: ") + header.message);
    header.format = PNG_FORMAT_RGBA;
    Image image;
    image.width = int(header.width);
    image.height = int(header.height);
    image.rgba.resize(PNG_IMAGE_SIZE(header));
    if (!png_image_finish_read(&header, nullptr, image.rgba.data(), 0, nullptr)) {
        png_image_free(&header);
        fail(file, std::string("cannot decode PNG: ") + header.message);
    }
    return image;
}

}  // namespace flexfit::viewer
