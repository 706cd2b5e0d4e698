#pragma once
// Random-case counts: the sanitizer build divides them by KOLIZE_TEST_SCALE (it is several
// times slower); the families and seeds stay the same.

#ifndef KOLIZE_TEST_SCALE
#define KOLIZE_TEST_SCALE 1
#endif

namespace kolize::narrowphase::testing {

constexpr int scaled(int count) {
    return count / KOLIZE_TEST_SCALE > 0 ? count / KOLIZE_TEST_SCALE : 1;
}

}  // namespace kolize::narrowphase::testing
