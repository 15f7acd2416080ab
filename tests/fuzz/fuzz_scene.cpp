// libFuzzer target: the scene parser must turn any bytes into either
// Settings or an InputError, never a crash, hang or other exception.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "accretion/core/error.h"
#include "accretion/scene/scene_parser.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    try {
        const accretion::Settings s = accretion::parseScene(text, "fuzz.toml");
        (void)accretion::settingsToToml(s);  // a parsed scene must also print
    } catch (const accretion::InputError&) {
    }
    return 0;
}
