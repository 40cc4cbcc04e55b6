#include "bake/run/bake_setup.h"

namespace gibake {

BakeSetup::BakeSetup() = default;
BakeSetup::~BakeSetup() = default;
BakeSetup::BakeSetup(BakeSetup&&) noexcept = default;
BakeSetup& BakeSetup::operator=(BakeSetup&&) noexcept = default;

}  // namespace gibake
