#include "accretion/io/png_file.h"

#include <csetjmp>
#include <cstdio>
#include <string>

#include <fmt/format.h>
#include <png.h>

#include "accretion/core/atomic_file.h"
#include "accretion/core/error.h"

namespace accretion {

namespace {

/// libpng reports an error by a long jump back into the function that set it
/// up; only plain C state lives between that setjmp and the jump.
[[noreturn]] void pngError(png_structp png, png_const_charp message) {
    auto* text = static_cast<char*>(png_get_error_ptr(png));
    std::snprintf(text, 256, "%s", message);
    std::longjmp(png_jmpbuf(png), 1);
}

void pngWarning(png_structp, png_const_charp) {}

/// Writes the PNG into `out`; on failure returns false with the reason in `error`.
bool writeTo(std::FILE* out, const std::uint8_t* rgb, std::uint32_t width, std::uint32_t height, const char* description,
             char error[256]) {
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, error, pngError, pngWarning);
    if (png == nullptr) return false;
    png_infop info = png_create_info_struct(png);
    if (info == nullptr || setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        return false;
    }
    png_init_io(png, out);
    png_set_IHDR(png, info, width, height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_text text{};
    if (description != nullptr && *description != '\0') {
        text.compression = PNG_TEXT_COMPRESSION_NONE;
        text.key = const_cast<char*>("Description");
        text.text = const_cast<char*>(description);
        png_set_text(png, info, &text, 1);
    }
    png_write_info(png, info);
    for (std::uint32_t y = 0; y < height; ++y) png_write_row(png, rgb + std::size_t(y) * width * 3);
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    return true;
}

}  // namespace

void writePng(const std::filesystem::path& file, const std::vector<std::uint8_t>& rgb, std::uint32_t width,
              std::uint32_t height, const std::string& description) {
    ACC_CHECK(rgb.size() == std::size_t(width) * height * 3 && width > 0 && height > 0);
    writeAtomicWith(file, [&](const std::filesystem::path& tmp) {
        std::FILE* out = std::fopen(tmp.c_str(), "wb");
        if (out == nullptr) throw InputError(fmt::format("{}: cannot write PNG", file.string()));
        char error[256] = "write failed";
        const bool ok = writeTo(out, rgb.data(), width, height, description.c_str(), error);
        const bool closed = std::fclose(out) == 0;
        if (!ok || !closed) throw InputError(fmt::format("{}: cannot write PNG: {}", file.string(), ok ? "write failed" : error));
    });
}

}  // namespace accretion
