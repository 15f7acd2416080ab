#pragma once
// What the command-line tests share: the binary, the scenes and the names
// they use (a test-only header: it brings names into scope on purpose).
#include <string>

#include <catch2/catch.hpp>
#include <OpenImageIO/imageio.h>

#include "support/test_scenes.h"

namespace OIIO = OIIO_NAMESPACE;
using Catch::Matchers::Contains;

namespace accretion::test {

inline const std::string kBin = programPath();
inline const std::string kScenes = std::string(ACCRETION_SOURCE_DIR) + "/scenes";

/// The small disk scene's text.
inline std::string tinyScene() { return smallDiskScene(); }

}  // namespace accretion::test
