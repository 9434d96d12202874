// SPDX-License-Identifier: MIT
// Baked height volumes over OpenVDB 10 (include/bumpgrad/volume.h). As in
// image.cc, no exception leaves an extern "C" function. The only OpenVDB
// templates instantiated are the two standard grid types, and the trilinear
// sampler is written out here instead of pulling in tools/Interpolation.h, to
// keep this (slow to compile) translation unit small.
#include "bumpgrad/volume.h"

#include <openvdb/openvdb.h>
#include <openvdb/io/File.h>
#include <openvdb/io/Stream.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <memory>
#include <mutex>
#include <new>
#include <string>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "io_util.h"

namespace vdb = openvdb;

static void init_vdb()
{
    // openvdb::initialize registers the grid types the file reader needs.
    static std::once_flag once;
    std::call_once(once, [] { vdb::initialize(); });
}

/* ---- writer ---------------------------------------------------------------- */

struct bg_vdb_writer {
    // Grids first: the accessors below refer to their trees and must die first.
    vdb::FloatGrid::Ptr height;
    vdb::Vec3SGrid::Ptr gradient;
    std::unique_ptr<vdb::FloatGrid::Accessor> hacc;
    std::unique_ptr<vdb::Vec3SGrid::Accessor> gacc;
    vdb::math::Transform::Ptr xform;
    std::string gradient_name;
    vdb::MetaMap meta; // user metadata, copied onto every grid when writing
};

bg_status bg_vdb_writer_create(double voxel_size, const double origin[3], const char *height_name,
                               const char *gradient_name, bg_vdb_writer **out)
{
    if (!out)
        return BG_ERR_NULL_POINTER;
    *out = nullptr;
    if (!(std::isfinite(voxel_size) && voxel_size > 0.0))
        return BG_ERR_INVALID_ARGUMENT;
    if (origin && !(std::isfinite(origin[0]) && std::isfinite(origin[1]) && std::isfinite(origin[2])))
        return BG_ERR_INVALID_ARGUMENT;
    try {
        init_vdb();
        auto w = std::make_unique<bg_vdb_writer>();
        w->xform = vdb::math::Transform::createLinearTransform(voxel_size);
        if (origin)
            w->xform->postTranslate(vdb::Vec3d(origin[0], origin[1], origin[2]));
        w->height = vdb::FloatGrid::create(0.0f);
        w->height->setTransform(w->xform);
        w->height->setName(height_name && *height_name ? height_name : "height");
        w->height->setGridClass(vdb::GRID_UNKNOWN);
        w->hacc = std::make_unique<vdb::FloatGrid::Accessor>(w->height->getAccessor());
        w->gradient_name = gradient_name && *gradient_name ? gradient_name : "gradient";
        *out = w.release();
        return BG_OK;
    } catch (const std::bad_alloc &) {
        return BG_ERR_OUT_OF_MEMORY;
    } catch (const std::exception &) {
        return BG_ERR_INVALID_ARGUMENT;
    }
}

bg_status bg_vdb_writer_add(bg_vdb_writer *w, const int32_t *i, const int32_t *j, const int32_t *k,
                            size_t n, const float *height, const float *gx, const float *gy,
                            const float *gz)
{
    if (!w || (n && (!i || !j || !k || !height)))
        return BG_ERR_NULL_POINTER;
    if (gx && (!gy || !gz))
        return BG_ERR_NULL_POINTER;
    try {
        if (gx && !w->gradient) {
            w->gradient = vdb::Vec3SGrid::create(vdb::Vec3s(0.0f));
            w->gradient->setTransform(w->xform);
            w->gradient->setName(w->gradient_name);
            // A gradient transforms like a covector (inverse-transpose), which
            // is what VEC_COVARIANT tells OpenVDB's transform tools.
            w->gradient->setVectorType(vdb::VEC_COVARIANT);
            w->gacc = std::make_unique<vdb::Vec3SGrid::Accessor>(w->gradient->getAccessor());
        }
        for (size_t t = 0; t < n; ++t) {
            const vdb::Coord c(i[t], j[t], k[t]);
            w->hacc->setValue(c, height[t]);
            if (gx)
                w->gacc->setValue(c, vdb::Vec3s(gx[t], gy[t], gz[t]));
        }
        return BG_OK;
    } catch (const std::bad_alloc &) {
        return BG_ERR_OUT_OF_MEMORY;
    }
}

bg_status bg_vdb_writer_set_meta(bg_vdb_writer *w, const char *key, const char *value)
{
    if (!w || !key || !value)
        return BG_ERR_NULL_POINTER;
    try {
        w->meta.insertMeta(key, vdb::StringMetadata(value));
        return BG_OK;
    } catch (const std::bad_alloc &) {
        return BG_ERR_OUT_OF_MEMORY;
    } catch (const std::exception &) {
        return BG_ERR_INVALID_ARGUMENT;
    }
}

uint64_t bg_vdb_writer_voxel_count(const bg_vdb_writer *w)
{
    return w ? static_cast<uint64_t>(w->height->activeVoxelCount()) : 0;
}

bg_status bg_vdb_writer_write(const bg_vdb_writer *w, const char *path, char *err, size_t errlen)
{
    bg_io_set_error(err, errlen, "%s", "");
    if (!w || !path) {
        bg_io_set_error(err, errlen, "bg_vdb_writer_write: NULL argument");
        return BG_ERR_NULL_POINTER;
    }
    std::string tmp;
    bg_status st = bg_io_make_temp(path, &tmp, err, errlen);
    if (st != BG_OK)
        return st;
    st = bg_io_guard("cannot write '" + std::string(path) + "'", "out of memory", "", BG_ERR_IO,
                     err, errlen, [&] {
        vdb::GridCPtrVec grids;
        // Same metadata on both grids: each stays self-describing if split off.
        for (vdb::GridBase::Ptr g : {vdb::GridBase::Ptr(w->height), vdb::GridBase::Ptr(w->gradient)}) {
            if (!g)
                continue;
            for (auto it = w->meta.beginMeta(); it != w->meta.endMeta(); ++it)
                g->insertMeta(it->first, *it->second);
            g->setCreator("bumpgrad " BG_IO_VERSION_STRING);
            grids.push_back(g);
        }
        vdb::io::File file(tmp);
        file.write(grids);
        file.close();
        // io::File does not report a short write (full disk, file size limit):
        // the finished temporary is read back in full before it may replace
        // anything.
        vdb::io::File check(tmp);
        check.open(false);
        size_t n = 0;
        for (auto it = check.beginName(); it != check.endName(); ++it, ++n)
            if (!check.readGrid(it.gridName()))
                throw std::runtime_error("a grid does not read back");
        check.close();
        if (n != grids.size())
            throw std::runtime_error("the file read back has another number of grids");
        return BG_OK;
    }, [&] { bg_io_discard_temp(tmp); });
    if (st != BG_OK)
        return st;
    return bg_io_commit_temp(tmp, path, err, errlen);
}

void bg_vdb_writer_free(bg_vdb_writer *w)
{
    delete w;
}

/* ---- reader ---------------------------------------------------------------- */

struct bg_vdb_height {
    vdb::FloatGrid::ConstPtr grid;
    // World -> index as an affine map (idx = a + M w), and the inverse-transpose
    // Jacobian taking an index-space gradient to world space; precomputed from
    // the linear transform so sampling makes no virtual calls.
    double w2i_off[3], w2i[3][3], ijt[3][3];
    bg_vdb_height_info info;
};

static std::string grid_list(const vdb::GridPtrVec &grids)
{
    std::string s;
    for (const auto &g : grids) {
        if (!s.empty())
            s += ", ";
        s += g->getName().empty() ? std::string("(unnamed)") : g->getName();
    }
    return s.empty() ? std::string("none") : s;
}

static bg_status open_impl(const char *path, const char *grid_name, bg_vdb_height **out, char *err,
                           size_t errlen)
{
    init_vdb();
    // Why a stream with exceptions and not io::File: OpenVDB does not check
    // its reads, so in a truncated file it takes whatever is left in a length
    // field past the end as a size and tries to allocate gigabytes (seen with
    // a file cut to 20%). With failbit raising, the first read past the end
    // throws instead. The stream reader loads every grid, which also checks
    // the whole file, at the cost of reading grids we then drop.
    vdb::GridPtrVecPtr grids;
    {
        std::ifstream is(path, std::ios::in | std::ios::binary);
        if (!is) {
            bg_io_set_error(err, errlen, "'%s': cannot open", path);
            return BG_ERR_IO;
        }
        is.exceptions(std::ios::failbit | std::ios::badbit);
        try {
            vdb::io::Stream stream(is, false);
            grids = stream.getGrids();
        } catch (const std::ios_base::failure &) {
            bg_io_set_error(err, errlen, "'%s': truncated or corrupt VDB file (read past its end)",
                            path);
            return BG_ERR_FORMAT;
        } catch (const std::bad_alloc &) {
            bg_io_set_error(err, errlen, "'%s': corrupt VDB file (or out of memory)", path);
            return BG_ERR_FORMAT;
        } catch (const std::exception &e) {
            bg_io_set_error(err, errlen, "'%s': not a VDB file, or corrupt (%s)", path, e.what());
            return BG_ERR_FORMAT;
        }
    }
    if (!grids)
        grids = std::make_shared<vdb::GridPtrVec>();
    vdb::GridBase::Ptr base;
    for (const auto &g : *grids) {
        if (!g)
            continue;
        if (grid_name && *grid_name ? g->getName() == grid_name : g->isType<vdb::FloatGrid>()) {
            base = g;
            break;
        }
    }
    if (!base) {
        if (grid_name && *grid_name)
            bg_io_set_error(err, errlen, "'%s': no grid named '%s' (grids: %s)", path, grid_name,
                            grid_list(*grids).c_str());
        else
            bg_io_set_error(err, errlen, "'%s': no float grid in the file (grids: %s)", path,
                            grid_list(*grids).c_str());
        return BG_ERR_FORMAT;
    }
    const std::string name = base->getName();
    vdb::FloatGrid::Ptr grid = vdb::gridPtrCast<vdb::FloatGrid>(base);
    if (!grid) {
        bg_io_set_error(err, errlen, "'%s': grid '%s' holds %s values, not float", path,
                        name.c_str(), base->valueType().c_str());
        return BG_ERR_FORMAT;
    }
    const vdb::math::Transform &xf = grid->transform();
    if (!xf.isLinear()) {
        bg_io_set_error(err, errlen, "'%s': grid '%s' has a non-linear (%s) transform", path,
                        name.c_str(), xf.mapType().c_str());
        return BG_ERR_FORMAT;
    }

    auto h = std::make_unique<bg_vdb_height>();
    h->grid = grid;
    const vdb::Vec3d o = xf.worldToIndex(vdb::Vec3d(0.0));
    for (int a = 0; a < 3; ++a) {
        vdb::Vec3d e(0.0);
        e[a] = 1.0;
        const vdb::Vec3d col = xf.worldToIndex(e) - o;
        const vdb::Vec3d g = xf.baseMap()->applyIJT(e);
        for (int r = 0; r < 3; ++r) {
            h->w2i[r][a] = col[r];
            h->ijt[r][a] = g[r];
        }
        h->w2i_off[a] = o[a];
    }
    bg_vdb_height_info &in = h->info;
    std::memset(&in, 0, sizeof in);
    const vdb::Vec3d vs = xf.voxelSize();
    const vdb::CoordBBox bb = grid->evalActiveVoxelBoundingBox();
    in.active_voxels = static_cast<uint64_t>(grid->activeVoxelCount());
    for (int a = 0; a < 3; ++a) {
        in.voxel_size[a] = vs[a];
        in.index_min[a] = bb.min()[a];
        in.index_max[a] = bb.max()[a];
    }
    if (in.active_voxels) {
        const vdb::BBoxd wb = xf.indexToWorld(bb);
        for (int a = 0; a < 3; ++a) {
            in.world_min[a] = wb.min()[a];
            in.world_max[a] = wb.max()[a];
        }
    }
    std::snprintf(in.name, sizeof in.name, "%s", name.c_str());
    *out = h.release();
    return BG_OK;
}

// OpenVDB 10 trusts the chunk lengths inside compressed streams: some corrupt
// files overflow its heap (glibc then aborts) instead of throwing. So the file
// is read once in a child process first; if that child dies of a signal, the
// file is reported as corrupt here instead of taking the command down. The
// child is given 60 s; the parent then reads the file for real.
static bg_status probe_in_child(const char *path, const char *grid_name, char *err, size_t errlen)
{
    std::fflush(nullptr);
    const pid_t parent = getpid();
    const unsigned timeout = bg_io_child_timeout();
    pid_t pid = fork();
    if (pid < 0)
        return BG_OK; // cannot probe: fall back to reading in-process
    if (pid == 0) {
        // A fuzzed 153 KB file once cost 2 GB here: the same address-space cap
        // as the mesh import child, a time-out, and death with the parent.
        bg_io_child_limits(parent, bg_io_child_memory_cap(path, "BUMPGRAD_VDB_MAX_MB"), timeout);
        int fd = ::open("/dev/null", O_WRONLY);
        if (fd >= 0)
            ::dup2(fd, 2); // the parent prints the one message
        bg_vdb_height *h = nullptr;
        char e[8];
        bg_status s;
        try {
            s = open_impl(path, grid_name, &h, e, sizeof e);
        } catch (...) {
            s = BG_ERR_FORMAT;
        }
        // A clean error is reproduced by the parent; running out of the cap is not
        // retried there without one.
        ::_exit(s == BG_OK ? 0 : s == BG_ERR_OUT_OF_MEMORY ? 4 : 3);
    }
    int status = 0;
    for (int waited_ms = 0;; waited_ms += 10) {
        pid_t r = ::waitpid(pid, &status, WNOHANG);
        if (r == pid)
            break;
        if (r < 0 && errno != EINTR)
            return BG_OK;
        if (waited_ms >= 1000 * static_cast<int>(timeout) + 1000) {
            // The status stays the child's (killed by SIGKILL): a time-out must
            // never fall through to reading the file in-process, without limits.
            ::kill(pid, SIGKILL);
            ::waitpid(pid, &status, 0);
            break;
        }
        struct timespec ts = {0, 10 * 1000 * 1000};
        nanosleep(&ts, nullptr);
    }
    if (WIFSIGNALED(status) && (WTERMSIG(status) == SIGALRM || WTERMSIG(status) == SIGKILL)) {
        bg_io_set_error(err, errlen,
                        "'%s': reading the VDB file took over %u s; giving up (set "
                        "BUMPGRAD_CHILD_TIMEOUT to allow more)", path, timeout);
        return BG_ERR_FORMAT;
    }
    if (WIFSIGNALED(status)) {
        bg_io_set_error(err, errlen, "'%s': corrupt VDB file (OpenVDB crashed reading it, signal %d)",
                        path, WTERMSIG(status));
        return BG_ERR_FORMAT;
    }
    if (WIFEXITED(status) && WEXITSTATUS(status) == 4) {
        bg_io_set_error(err, errlen,
                        "'%s': reading the VDB file needs more memory than a file of this size "
                        "should (corrupt counts?); set BUMPGRAD_VDB_MAX_MB to allow more", path);
        return BG_ERR_FORMAT;
    }
    // 0: the file reads; 3: a clean error, which the parent reproduces with its
    // message. Any other status (an abort in a library, an allocator giving up)
    // is a failed probe, never a reason to read the file in-process.
    if (!WIFEXITED(status) || (WEXITSTATUS(status) != 0 && WEXITSTATUS(status) != 3)) {
        bg_io_set_error(err, errlen, "'%s': corrupt VDB file (reading it failed with status %d)",
                        path, WIFEXITED(status) ? WEXITSTATUS(status) : -1);
        return BG_ERR_FORMAT;
    }
    return BG_OK;
}

bg_status bg_vdb_height_open(const char *path, const char *grid_name, bg_vdb_height **out,
                             char *err, size_t errlen)
{
    bg_io_set_error(err, errlen, "%s", "");
    if (!path || !out) {
        bg_io_set_error(err, errlen, "bg_vdb_height_open: NULL argument");
        return BG_ERR_NULL_POINTER;
    }
    *out = nullptr;
    bg_status st = bg_io_check_readable(path, nullptr, err, errlen);
    if (st != BG_OK)
        return st;
    st = probe_in_child(path, grid_name, err, errlen);
    if (st != BG_OK)
        return st;
    return bg_io_guard("'" + std::string(path) + "'", "out of memory",
                       "corrupt or truncated VDB file", BG_ERR_FORMAT, err, errlen,
                       [&] { return open_impl(path, grid_name, out, err, errlen); });
}

void bg_vdb_height_close(bg_vdb_height *h)
{
    delete h;
}

void bg_vdb_height_get_info(const bg_vdb_height *h, bg_vdb_height_info *info)
{
    if (h && info)
        *info = h->info;
}

// Trilinear interpolation in a 3x3x3 block, local coordinates in [0, 2].
static double tri(const float v[3][3][3], double u, double s, double t)
{
    const int a = u < 1.0 ? 0 : 1, b = s < 1.0 ? 0 : 1, c = t < 1.0 ? 0 : 1;
    const double fu = u - a, fs = s - b, ft = t - c;
    double x[2][2];
    for (int q = 0; q < 2; ++q)
        for (int r = 0; r < 2; ++r)
            x[q][r] = v[a][b + q][c + r] + fu * (static_cast<double>(v[a + 1][b + q][c + r]) -
                                                 v[a][b + q][c + r]);
    const double y0 = x[0][0] + fs * (x[1][0] - x[0][0]);
    const double y1 = x[0][1] + fs * (x[1][1] - x[0][1]);
    return y0 + ft * (y1 - y0);
}

void bg_vdb_height_sample_batch(const bg_vdb_height *h, const float *px, const float *py,
                                const float *pz, size_t n, float *height, float *gx, float *gy,
                                float *gz)
{
    if (!h || n == 0)
        return;
    // Unsafe (unregistered) accessor: the tree never changes after open, and
    // each call has its own, which is what makes concurrent calls safe.
    auto acc = h->grid->getConstUnsafeAccessor();
    const float bg = h->grid->background();
    // Index coordinates beyond this are far outside any tree: background.
    const double lim = 2147483000.0;
    for (size_t t = 0; t < n; ++t) {
        const double w[3] = {px[t], py[t], pz[t]};
        if (!(std::isfinite(w[0]) && std::isfinite(w[1]) && std::isfinite(w[2]))) {
            const float nan = std::nanf("");
            if (height)
                height[t] = nan;
            if (gx)
                gx[t] = gy[t] = gz[t] = nan;
            continue;
        }
        double p[3];
        bool far = false;
        for (int r = 0; r < 3; ++r) {
            p[r] = h->w2i_off[r] + h->w2i[r][0] * w[0] + h->w2i[r][1] * w[1] + h->w2i[r][2] * w[2];
            far = far || !(std::fabs(p[r]) < lim);
        }
        if (far) {
            if (height)
                height[t] = bg;
            if (gx)
                gx[t] = gy[t] = gz[t] = 0.0f;
            continue;
        }
        // Block corner c = floor(p - 0.5): the samples at p and p +- 0.5 along
        // each axis all fall in voxels c .. c+2.
        int c[3];
        double l[3];
        for (int r = 0; r < 3; ++r) {
            const double f = std::floor(p[r] - 0.5);
            c[r] = static_cast<int>(f);
            l[r] = p[r] - f;
        }
        float v[3][3][3];
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b)
                for (int d = 0; d < 3; ++d)
                    v[a][b][d] = acc.getValue(vdb::Coord(c[0] + a, c[1] + b, c[2] + d));
        if (height)
            height[t] = static_cast<float>(tri(v, l[0], l[1], l[2]));
        if (gx) {
            const double gi[3] = {
                tri(v, l[0] + 0.5, l[1], l[2]) - tri(v, l[0] - 0.5, l[1], l[2]),
                tri(v, l[0], l[1] + 0.5, l[2]) - tri(v, l[0], l[1] - 0.5, l[2]),
                tri(v, l[0], l[1], l[2] + 0.5) - tri(v, l[0], l[1], l[2] - 0.5)};
            float *o[3] = {gx, gy, gz};
            for (int r = 0; r < 3; ++r)
                o[r][t] = static_cast<float>(h->ijt[r][0] * gi[0] + h->ijt[r][1] * gi[1] +
                                             h->ijt[r][2] * gi[2]);
        }
    }
}
