# SPDX-License-Identifier: MIT
"""A numpy float64 reference of Perlin's improved noise (SIGGRAPH 2002), written
from his published Java code, not from src/ nor tests/ref: the value follows his
lerp chain operation for operation (so it equals his reference bit for bit in
double), the gradient is the derivative of the trilinear form
sum_c w_c(u, v, w) (g_c . d_c), and fBm / turbulence follow Perlin 1985:
sum_i gain^i n(lacunarity^i p) (|n| for turbulence)."""
import numpy as np

# Perlin's permutation from "Improving Noise" (2002).
PERM = np.array([
    151, 160, 137, 91, 90, 15, 131, 13, 201, 95, 96, 53, 194, 233, 7, 225, 140, 36, 103, 30, 69,
    142, 8, 99, 37, 240, 21, 10, 23, 190, 6, 148, 247, 120, 234, 75, 0, 26, 197, 62, 94, 252, 219,
    203, 117, 35, 11, 32, 57, 177, 33, 88, 237, 149, 56, 87, 174, 20, 125, 136, 171, 168, 68, 175,
    74, 165, 71, 134, 139, 48, 27, 166, 77, 146, 158, 231, 83, 111, 229, 122, 60, 211, 133, 230,
    220, 105, 92, 41, 55, 46, 245, 40, 244, 102, 143, 54, 65, 25, 63, 161, 1, 216, 80, 73, 209, 76,
    132, 187, 208, 89, 18, 169, 200, 196, 135, 130, 116, 188, 159, 86, 164, 100, 109, 198, 173,
    186, 3, 64, 52, 217, 226, 250, 124, 123, 5, 202, 38, 147, 118, 126, 255, 82, 85, 212, 207, 206,
    59, 227, 47, 16, 58, 17, 182, 189, 28, 42, 223, 183, 170, 213, 119, 248, 152, 2, 44, 154, 163,
    70, 221, 153, 101, 155, 167, 43, 172, 9, 129, 22, 39, 253, 19, 98, 108, 110, 79, 113, 224, 232,
    178, 185, 112, 104, 218, 246, 97, 228, 251, 34, 242, 193, 238, 210, 144, 12, 191, 179, 162,
    241, 81, 51, 145, 235, 249, 14, 239, 107, 49, 192, 214, 31, 181, 199, 106, 157, 184, 84, 204,
    176, 115, 121, 50, 45, 127, 4, 150, 254, 138, 236, 205, 93, 222, 114, 67, 29, 24, 72, 243,
    141, 128, 195, 78, 66, 215, 61, 156, 180], dtype=np.int64)
assert len(PERM) == 256 and len(set(PERM.tolist())) == 256
P = np.concatenate([PERM, PERM])


def _fade(t):
    return t * t * t * (t * (t * 6 - 15) + 10)


def _dfade(t):
    return 30 * t * t * (t * (t - 2) + 1)


def _lerp(t, a, b):
    return a + t * (b - a)


def _grad(h, x, y, z):
    h = h & 15
    u = np.where(h < 8, x, y)
    v = np.where(h < 4, y, np.where((h == 12) | (h == 14), x, z))
    return np.where(h & 1 == 0, u, -u) + np.where(h & 2 == 0, v, -v)


def _gvec(h):
    """The corner's gradient vector: grad() is linear in its offset, so evaluate
    it on the unit vectors."""
    one, zero = np.ones(h.shape), np.zeros(h.shape)
    return [_grad(h, one, zero, zero), _grad(h, zero, one, zero), _grad(h, zero, zero, one)]


def noise(x, y, z, grad=False):
    x, y, z = (np.asarray(a, np.float64) for a in (x, y, z))
    fx, fy, fz = np.floor(x), np.floor(y), np.floor(z)
    X = np.mod(fx, 256).astype(np.int64)
    Y = np.mod(fy, 256).astype(np.int64)
    Z = np.mod(fz, 256).astype(np.int64)
    x, y, z = x - fx, y - fy, z - fz
    u, v, w = _fade(x), _fade(y), _fade(z)
    A = P[X] + Y
    AA, AB = P[A] + Z, P[A + 1] + Z
    B = P[X + 1] + Y
    BA, BB = P[B] + Z, P[B + 1] + Z
    value = _lerp(w, _lerp(v, _lerp(u, _grad(P[AA], x, y, z), _grad(P[BA], x - 1, y, z)),
                          _lerp(u, _grad(P[AB], x, y - 1, z), _grad(P[BB], x - 1, y - 1, z))),
                  _lerp(v, _lerp(u, _grad(P[AA + 1], x, y, z - 1), _grad(P[BA + 1], x - 1, y, z - 1)),
                        _lerp(u, _grad(P[AB + 1], x, y - 1, z - 1),
                              _grad(P[BB + 1], x - 1, y - 1, z - 1))))
    if not grad:
        return value
    du, dv, dw = _dfade(x), _dfade(y), _dfade(z)
    g = [np.zeros(x.shape) for _ in range(3)]
    corners = {(0, 0, 0): P[AA], (1, 0, 0): P[BA], (0, 1, 0): P[AB], (1, 1, 0): P[BB],
               (0, 0, 1): P[AA + 1], (1, 0, 1): P[BA + 1], (0, 1, 1): P[AB + 1],
               (1, 1, 1): P[BB + 1]}
    for (i, j, k), h in corners.items():
        gv = _gvec(h)
        d = (x - i, y - j, z - k)
        dot = gv[0] * d[0] + gv[1] * d[1] + gv[2] * d[2]
        wx, wy, wz = (u if i else 1 - u), (v if j else 1 - v), (w if k else 1 - w)
        sx, sy, sz = (1 if i else -1), (1 if j else -1), (1 if k else -1)
        g[0] += sx * du * wy * wz * dot + wx * wy * wz * gv[0]
        g[1] += wx * sy * dv * wz * dot + wx * wy * wz * gv[1]
        g[2] += wx * wy * sz * dw * dot + wx * wy * wz * gv[2]
    return value, g


def fractal(x, y, z, function="fbm", octaves=6, lacunarity=2.0, gain=0.5):
    """(value, gradient, smallest |octave value|) in float64; the last tells
    where turbulence has a crease (|n_i| = 0) so a test can skip those points."""
    x, y, z = (np.asarray(a, np.float64) for a in (x, y, z))
    if function == "noise":
        octaves = 1
    total = np.zeros(x.shape)
    g = [np.zeros(x.shape) for _ in range(3)]
    minabs = np.full(x.shape, np.inf)
    amp, freq = 1.0, 1.0
    for _ in range(octaves):
        n, gn = noise(freq * x, freq * y, freq * z, grad=True)
        s = np.where(n >= 0, 1.0, -1.0) if function == "turbulence" else 1.0
        total += amp * (np.abs(n) if function == "turbulence" else n)
        for a in range(3):
            g[a] += s * amp * freq * gn[a]
        minabs = np.minimum(minabs, np.abs(n))
        amp *= float(np.float32(gain))
        freq *= float(np.float32(lacunarity))
    return total, g, minabs
