// SPDX-License-Identifier: MIT
// A C++ program that uses bumpgrad as a CMake user would: through the installed
// package (find_package or pkg_check_modules), nothing from the source tree.
// Prints Perlin's reference value and checks it, and a perturbed normal.
#include <bumpgrad.h>

#include <cmath>
#include <cstdio>
#include <cstring>

int main()
{
    const double v = bg_noise3d(3.14, 42.0, 7.0);
    std::printf("bumpgrad %s: noise3d(3.14, 42, 7) = %.17g\n", bg_version_string(), v);
    if (v != 0.13691995878400012) {
        std::printf("FAIL: expected 0.13691995878400012\n");
        return 1;
    }
    bg_vec3 n = {0.0f, 0.0f, 1.0f}, g = {0.5f, 0.0f, 3.0f};
    bg_vec3 r = bg_perturb_normal(n, g);
    const float len = std::sqrt(r.x * r.x + r.y * r.y + r.z * r.z);
    std::printf("perturb_normal = (%.6f, %.6f, %.6f)\n", r.x, r.y, r.z);
    if (std::fabs(len - 1.0f) > 1e-6f || !(r.z > 0.0f) || !(r.x < 0.0f)) {
        std::printf("FAIL: not a unit normal leaning against the gradient\n");
        return 1;
    }
    if (std::strcmp(bg_status_string(BG_OK), bg_status_string(BG_ERR_IO)) == 0)
        return 1;
    return 0;
}
