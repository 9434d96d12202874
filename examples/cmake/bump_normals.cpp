// SPDX-License-Identifier: MIT
// bump_normals: bumpgrad from C++ (the C API, std::vector buffers). Bumps the
// normals of points on a unit sphere with 6-octave turbulence in one fused,
// SIMD batch call (surface gradient, Mikkelsen 2010 eq. 4), then checks each
// result against the single-point calls: height, analytic gradient and
// bg_perturb_normal. Prints a few normals and the largest angle between the
// two paths.
//
//   cmake -S examples/cmake -B build-example -DCMAKE_PREFIX_PATH=PREFIX
//   cmake --build build-example && build-example/bump_normals [count]
#include <bumpgrad.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

int main(int argc, char **argv)
{
    const std::size_t n = argc > 1 ? std::strtoul(argv[1], nullptr, 10) : 100000;
    if (n == 0 || n > 100000000) {
        std::fprintf(stderr, "usage: bump_normals [count 1..1e8]\n");
        return 2;
    }
    // Points on a Fibonacci spiral over the unit sphere; there the normal is the position.
    std::vector<float> px(n), py(n), pz(n), height(n), ox(n), oy(n), oz(n);
    const double golden = 3.14159265358979 * (3.0 - std::sqrt(5.0));
    for (std::size_t i = 0; i < n; i++) {
        double z = 1.0 - 2.0 * (i + 0.5) / n, r = std::sqrt(1.0 - z * z), a = golden * i;
        px[i] = float(r * std::cos(a)), py[i] = float(r * std::sin(a)), pz[i] = float(z);
    }

    bg_height h = bg_height_default(); // 6-octave turbulence, amplitude 0.1
    h.frequency = 4.0f;
    bg_status s = bg_perturb_height_batch(&h, BG_PERTURB_SURFGRAD, px.data(), py.data(), pz.data(),
                                          px.data(), py.data(), pz.data(), n, height.data(),
                                          ox.data(), oy.data(), oz.data());
    if (s != BG_OK) {
        std::fprintf(stderr, "bg_perturb_height_batch: %s\n", bg_status_string(s));
        return 1;
    }

    double worst = 0, mean_tilt = 0;
    for (std::size_t i = 0; i < n; i++) {
        bg_vec3 p = {px[i], py[i], pz[i]}, g;
        float hv = bg_height_eval(&h, p, &g);
        bg_vec3 one = bg_perturb_normal(p, g), batch = {ox[i], oy[i], oz[i]};
        double d = bg_angle_deg(one, batch);
        worst = d > worst || std::isnan(d) ? d : worst;
        mean_tilt += bg_angle_deg(p, batch) / n;
        if (hv != height[i])
            worst = NAN;
        if (i < 3)
            std::printf("p = (%+.4f, %+.4f, %+.4f)  h = %+.5f  n' = (%+.4f, %+.4f, %+.4f)\n", p.x,
                        p.y, p.z, height[i], batch.x, batch.y, batch.z);
    }
    std::printf("bumpgrad %s (ISA %s): %zu normals, mean tilt %.2f deg, batch vs single-point "
                "calls: largest angle %.3g deg\n",
                bg_version_string(), bg_isa_name(bg_isa_active()), n, mean_tilt, worst);
    // The batch gives the bits of the single-point calls (noise.h): any difference is a bug.
    return worst == 0.0 ? 0 : 1;
}
