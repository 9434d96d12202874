// SPDX-License-Identifier: MIT
// The VDB layout walk of the I/O shim (src/io/volume.cc, check_vdb_layout:
// every length field before the trees is checked against the file before
// OpenVDB allocates by it) against OpenVDB's own writer. Every variant that
// OpenVDB 10 writes and reads back must open through bg_vdb_height_open:
// metadata of every registered type, a half-float grid, an instanced grid,
// no / zip / blosc compression, io::Stream (no grid offsets), delayed-load
// metadata below and above blosc's padding size (1 to 10^4 leaves). Then one
// valid file with a metadata name length made to run past its end, and one
// with its file_mem_bytes over BUMPGRAD_MAX_MB, must each be refused with a
// message naming the file.
//
// Usage: test_vdb_layout SCRATCH_DIR
#include <openvdb/openvdb.h>
#include <openvdb/io/File.h>
#include <openvdb/io/Stream.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <unistd.h>

#include "bumpgrad/volume.h"

using namespace openvdb;

static int failures = 0;

static void check(bool ok, const std::string &what)
{
    std::printf("%s: %s\n", ok ? "ok" : "FAIL", what.c_str());
    if (!ok)
        ++failures;
}

// n x n active voxels spread over about n^2 / 8^3 leaves.
static FloatGrid::Ptr height_grid(int n)
{
    FloatGrid::Ptr g = FloatGrid::create(0.0f);
    FloatGrid::Accessor a = g->getAccessor();
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
            a.setValue(Coord(i * 9, j * 9, i + j), static_cast<float>(i - j));
    g->setName("height");
    return g;
}

static void add_every_meta_type(GridBase &g)
{
    g.insertMeta("s", StringMetadata("hello"));
    g.insertMeta("empty", StringMetadata(""));
    g.insertMeta("b", BoolMetadata(true));
    g.insertMeta("f", FloatMetadata(0.5f));
    g.insertMeta("d", DoubleMetadata(1.5));
    g.insertMeta("i32", Int32Metadata(7));
    g.insertMeta("i64", Int64Metadata(-7));
    g.insertMeta("v2i", Vec2IMetadata(Vec2i(1, 2)));
    g.insertMeta("v2s", Vec2SMetadata(Vec2s(1, 2)));
    g.insertMeta("v2d", Vec2DMetadata(Vec2d(1, 2)));
    g.insertMeta("v3i", Vec3IMetadata(Vec3i(1, 2, 3)));
    g.insertMeta("v3s", Vec3SMetadata(Vec3s(1, 2, 3)));
    g.insertMeta("v3d", Vec3DMetadata(Vec3d(1, 2, 3)));
    g.insertMeta("v4i", Vec4IMetadata(Vec4i(1, 2, 3, 4)));
    g.insertMeta("v4s", Vec4SMetadata(Vec4s(1, 2, 3, 4)));
    g.insertMeta("v4d", Vec4DMetadata(Vec4d(1, 2, 3, 4)));
    g.insertMeta("m4s", Mat4SMetadata(math::Mat4s::identity()));
    g.insertMeta("m4d", Mat4DMetadata(math::Mat4d::identity()));
}

static std::vector<char> slurp(const std::string &path)
{
    std::ifstream is(path, std::ios::binary);
    return std::vector<char>(std::istreambuf_iterator<char>(is), std::istreambuf_iterator<char>());
}

static void spit(const std::string &path, const std::vector<char> &data)
{
    std::ofstream os(path, std::ios::binary);
    os.write(data.data(), static_cast<std::streamsize>(data.size()));
}

// Opens through the shim; returns the status, the message in *msg.
static bg_status open_status(const std::string &path, std::string *msg)
{
    bg_vdb_height *h = nullptr;
    char err[512];
    bg_status st = bg_vdb_height_open(path.c_str(), nullptr, &h, err, sizeof err);
    *msg = err;
    bg_vdb_height_close(h);
    return st;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        std::fprintf(stderr, "usage: test_vdb_layout SCRATCH_DIR\n");
        return 2;
    }
    initialize();
    std::string dir = std::string(argv[1]) + "/test_vdb_layout_XXXXXX";
    if (!mkdtemp(&dir[0])) {
        std::perror("mkdtemp");
        return 1;
    }
    std::vector<std::string> written;
    for (int n : {1, 4, 12, 40, 100}) {
        for (int variant = 0; variant < 7; ++variant) {
            const std::string path =
                dir + "/v" + std::to_string(n) + "_" + std::to_string(variant) + ".vdb";
            FloatGrid::Ptr h = height_grid(n);
            Vec3SGrid::Ptr grad = Vec3SGrid::create();
            grad->setName("gradient");
            grad->tree().setValue(Coord(1, 2, 3), Vec3s(1, 2, 3));
            GridPtrVec grids;
            grids.push_back(h);
            MetaMap file_meta;
            file_meta.insertMeta("note", StringMetadata("x"));
            file_meta.insertMeta("v3i", Vec3IMetadata(Vec3i(1, 2, 3)));
            io::File f(path);
            const char *what = "blosc";
            switch (variant) {
            case 1:
                add_every_meta_type(*h);
                grids.push_back(grad);
                what = "every metadata type, two grids";
                break;
            case 2:
                h->setSaveFloatAsHalf(true);
                what = "half float";
                break;
            case 3: {
                GridBase::Ptr inst = h->copyGrid(); // shares the tree: an instance
                inst->setName("instance");
                grids.push_back(inst);
                grids.push_back(grad);
                what = "an instanced grid";
                break;
            }
            case 4:
                f.setCompression(io::COMPRESS_NONE);
                what = "no compression";
                break;
            case 5:
                f.setCompression(io::COMPRESS_ZIP | io::COMPRESS_ACTIVE_MASK);
                what = "zip";
                break;
            default:
                break;
            }
            if (variant == 6) {
                std::ofstream os(path, std::ios::binary);
                io::Stream(os).write(grids, file_meta);
                what = "io::Stream, no grid offsets";
            } else {
                f.write(grids, file_meta);
                f.close();
            }
            std::string msg;
            bg_status st = open_status(path, &msg);
            check(st == BG_OK, std::to_string(n * n) + " voxels, " + what + " (" +
                                   std::to_string(h->tree().leafCount()) + " leaves): opens" +
                                   (st == BG_OK ? "" : ": " + msg));
            written.push_back(path);
        }
    }

    // A metadata name length made to run past the end of a valid file.
    const std::string base = dir + "/v40_1.vdb";
    std::vector<char> data = slurp(base);
    const std::string key = std::string("\x0e\0\0\0file_mem_bytes", 18);
    auto at = std::search(data.begin(), data.end(), key.begin(), key.end());
    check(at != data.end(), "the test file has file_mem_bytes metadata");
    if (at != data.end()) {
        std::vector<char> bad = data;
        const size_t k = static_cast<size_t>(at - data.begin());
        bad[k + 3] = 0x7f; // length 0x7f00000e
        const std::string p = dir + "/long_name.vdb";
        spit(p, bad);
        written.push_back(p);
        std::string msg;
        bg_status st = open_status(p, &msg);
        check(st == BG_ERR_FORMAT && msg.find("long_name.vdb") != std::string::npos &&
                  msg.find("runs past the end") != std::string::npos,
              "a metadata name longer than the file is refused (" + msg + ")");

        // file_mem_bytes of 2^50 bytes: over the cap, refused before reading.
        bad = data;
        const size_t v = k + key.size() + 4 + 5 + 4; // type "int64", its size field
        check(std::memcmp(&bad[k + key.size()], "\x05\0\0\0int64", 9) == 0,
              "file_mem_bytes is an int64");
        const int64_t huge = int64_t(1) << 50;
        std::memcpy(&bad[v], &huge, sizeof huge);
        const std::string q = dir + "/mem_bytes.vdb";
        spit(q, bad);
        written.push_back(q);
        st = open_status(q, &msg);
        check(st == BG_ERR_FORMAT && msg.find("mem_bytes.vdb") != std::string::npos &&
                  msg.find("file_mem_bytes") != std::string::npos &&
                  msg.find("BUMPGRAD_MAX_MB") != std::string::npos,
              "file_mem_bytes of 2^50 bytes is over the cap (" + msg + ")");
    }

    for (const std::string &p : written)
        unlink(p.c_str());
    rmdir(dir.c_str());
    std::printf("test_vdb_layout: %s\n", failures ? "FAILED" : "all checks passed");
    return failures ? 1 : 0;
}
