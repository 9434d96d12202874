// SPDX-License-Identifier: MIT
// Baked height volumes over OpenVDB 10 (include/bumpgrad/volume.h). As in
// image.cc, no exception leaves an extern "C" function. The only OpenVDB
// templates instantiated are the two standard grid types, and the trilinear
// sampler is written out here instead of pulling in tools/Interpolation.h, to
// keep this (slow to compile) translation unit small.
#include "bumpgrad/volume.h"

#include <openvdb/openvdb.h>
#include <openvdb/io/DelayedLoadMetadata.h>
#include <openvdb/io/File.h>
#include <openvdb/io/Stream.h>
#include <openvdb/points/StreamCompression.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <memory>
#include <mutex>
#include <new>
#include <string>
#include <vector>

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
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

// The one VDB file writer: `collect` fills the grids (inside the exception
// guard), which go to a temporary next to `path`; io::File does not report a
// short write (full disk, file size limit), so the finished temporary is read
// back in full before it may replace anything.
template <class Collect>
static bg_status write_grids(const char *path, Collect collect, char *err, size_t errlen)
{
    std::string tmp;
    bg_status st = bg_io_make_temp(path, &tmp, err, errlen);
    if (st != BG_OK)
        return st;
    st = bg_io_guard("cannot write '" + std::string(path) + "'", "out of memory", "", BG_ERR_IO,
                     err, errlen, [&] {
        vdb::GridCPtrVec grids;
        collect(grids);
        vdb::io::File file(tmp);
        file.write(grids);
        file.close();
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

bg_status bg_vdb_writer_write(const bg_vdb_writer *w, const char *path, char *err, size_t errlen)
{
    bg_io_set_error(err, errlen, "%s", "");
    if (!w || !path) {
        bg_io_set_error(err, errlen, "bg_vdb_writer_write: NULL argument");
        return BG_ERR_NULL_POINTER;
    }
    return write_grids(path, [&](vdb::GridCPtrVec &grids) {
        // Same metadata on both grids: each stays self-describing if split off.
        for (vdb::GridBase::Ptr g : {vdb::GridBase::Ptr(w->height), vdb::GridBase::Ptr(w->gradient)}) {
            if (!g)
                continue;
            for (auto it = w->meta.beginMeta(); it != w->meta.endMeta(); ++it)
                g->insertMeta(it->first, *it->second);
            g->setCreator("bumpgrad " BG_IO_VERSION_STRING);
            grids.push_back(g);
        }
    }, err, errlen);
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

// How reading every grid of a file through a stream ended (read_grid_stream).
enum class stream_read { ok, cannot_open, past_end, no_memory, corrupt };

// The one reader of whole VDB files (the height reader's and the merge's):
// every grid of `path` through a stream with exceptions on. Why not
// io::File: OpenVDB does not check its reads, so in a truncated file it takes
// whatever is left in a length field past the end as a size and tries to
// allocate gigabytes (seen with a file cut to 20%). With failbit raising, the
// first read past the end throws instead. The stream reader loads every grid,
// which also checks the whole file, at the cost of reading grids a caller
// may drop. `what` gets the exception's text of a corrupt file.
static stream_read read_grid_stream(const char *path, vdb::GridPtrVecPtr *grids, char *what,
                                    size_t whatlen)
{
    std::ifstream is(path, std::ios::in | std::ios::binary);
    if (!is)
        return stream_read::cannot_open;
    is.exceptions(std::ios::failbit | std::ios::badbit);
    try {
        vdb::io::Stream stream(is, false);
        *grids = stream.getGrids();
        return stream_read::ok;
    } catch (const std::ios_base::failure &) {
        return stream_read::past_end;
    } catch (const std::bad_alloc &) {
        return stream_read::no_memory;
    } catch (const std::exception &e) {
        std::snprintf(what, whatlen, "%s", e.what());
        return stream_read::corrupt;
    }
}

static bg_status open_impl(const char *path, const char *grid_name, bg_vdb_height **out, char *err,
                           size_t errlen)
{
    init_vdb();
    vdb::GridPtrVecPtr grids;
    char what[1024];
    switch (read_grid_stream(path, &grids, what, sizeof what)) {
    case stream_read::ok:
        break;
    case stream_read::cannot_open:
        bg_io_set_error(err, errlen, "'%s': cannot open", path);
        return BG_ERR_IO;
    case stream_read::past_end:
        bg_io_set_error(err, errlen, "'%s': truncated or corrupt VDB file (read past its end)",
                        path);
        return BG_ERR_FORMAT;
    case stream_read::no_memory:
        // OUT_OF_MEMORY, not FORMAT: in the probe child that is exit 4,
        // which the parent must not retry without the child's cap.
        bg_io_set_error(err, errlen, "'%s': corrupt VDB file (or out of memory)", path);
        return BG_ERR_OUT_OF_MEMORY;
    case stream_read::corrupt:
        bg_io_set_error(err, errlen, "'%s': not a VDB file, or corrupt (%s)", path, what);
        return BG_ERR_FORMAT;
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

/* ---- the container walk before OpenVDB reads a file --------------------------
 * OpenVDB 10 trusts every length field: readString (Name.h) and the string
 * metadata allocate and zero the declared size before reading it, and
 * DelayedLoadMetadata sizes two arrays by a count read from the file. So a
 * 20 KB file whose metadata name length reads 0x656d616e ("name", one field
 * shifted) made it allocate and memset 1.7 GB, in the probe child (under its
 * 2 GiB cap) and again in the parent, before failing at the end of the file
 * (tests/fuzz/regress/vdb/vdb-meta-string-1.7GB). OpenVDB's own metadata-only
 * reads (io::File::open, readAllGridMetadata) go through the same readMeta, so
 * they cannot be the pre-check. This walk follows the layout io::Stream reads
 * (Archive::readHeader, MetaMap::readMeta, GridDescriptor::read,
 * Archive::readGrid up to the transform), checking each length against the
 * bytes that remain before anything is allocated, and adds up the grids'
 * file_mem_bytes (their in-memory size, written by OpenVDB) for the one
 * allocation cap (BUMPGRAD_MAX_MB). It stops at each tree: the topology and
 * the leaf buffers are left to the probe child's address-space cap. With grid
 * offsets (every file io::File writes) it finds the next grid at the
 * descriptor's end offset; without them it checks the first grid only. */
namespace {

struct vdb_layout_error {
    std::string msg;
};

class vdb_layout {
  public:
    vdb_layout(FILE *f, uint64_t size) : f_(f), size_(size) {}

    uint64_t pos() const { return pos_; }
    uint64_t size() const { return size_; }

    [[noreturn]] void fail(const char *fmt, ...) BG_IO_PRINTF(2, 3)
    {
        char buf[256];
        va_list ap;
        va_start(ap, fmt);
        std::vsnprintf(buf, sizeof buf, fmt, ap);
        va_end(ap);
        throw vdb_layout_error{buf};
    }

    // n more bytes must be in the file for `what`.
    void need(uint64_t n, const char *what)
    {
        if (n > size_ - pos_)
            fail("at byte %llu, %s of %llu bytes runs past the end of the file (%llu bytes)",
                 static_cast<unsigned long long>(pos_), what, static_cast<unsigned long long>(n),
                 static_cast<unsigned long long>(size_));
    }
    void bytes(void *p, size_t n, const char *what)
    {
        need(n, what);
        if (std::fread(p, 1, n, f_) != n)
            fail("at byte %llu: read error (%s)", static_cast<unsigned long long>(pos_),
                 std::strerror(errno));
        pos_ += n;
    }
    void skip(uint64_t n, const char *what)
    {
        need(n, what);
        seek(pos_ + n);
    }
    void seek(uint64_t to)
    {
        if (to > size_ || fseeko(f_, static_cast<off_t>(to), SEEK_SET) != 0)
            fail("cannot seek to byte %llu", static_cast<unsigned long long>(to));
        pos_ = to;
    }
    template <class T> T value(const char *what)
    {
        T v;
        bytes(&v, sizeof v, what);
        return v;
    }
    // A readString field: uint32 length, then the bytes. Only short strings
    // (names, type names) are kept; a longer one is checked and skipped.
    std::string string(const char *what)
    {
        const uint32_t n = value<uint32_t>(what);
        need(n, what);
        if (n > 256) {
            skip(n, what);
            return std::string();
        }
        std::string s(n, '\0');
        if (n)
            bytes(&s[0], n, what);
        return s;
    }
    // The next character `is >> c` would give (boost's uuid reader skips
    // white space before each one).
    int word_char()
    {
        for (;;) {
            const unsigned char c = value<unsigned char>("the header's uuid");
            if (!std::isspace(c))
                return c;
        }
    }

  private:
    FILE *f_;
    uint64_t size_;
    uint64_t pos_ = 0;
};

// The blosc header's uncompressed size (bytes 4..7) of a compressed block of
// `n` bytes, which OpenVDB reserves before decompressing.
uint32_t blosc_uncompressed(vdb_layout &r, uint32_t n, const char *what)
{
    if (n < 16)
        r.fail("at byte %llu, %s is %u bytes, shorter than a blosc header",
               static_cast<unsigned long long>(r.pos()), what, n);
    unsigned char h[16];
    r.bytes(h, sizeof h, what);
    r.skip(n - 16, what);
    return static_cast<uint32_t>(h[4]) | static_cast<uint32_t>(h[5]) << 8 |
           static_cast<uint32_t>(h[6]) << 16 | static_cast<uint32_t>(h[7]) << 24;
}

// DelayedLoadMetadata::readValue: a leaf count, the leaves' mask bytes and
// their compressed sizes (int64), each raw or blosc-compressed, then any
// bytes up to numBytes. OpenVDB sizes both arrays by the count (4 G leaves:
// 36 GB): a file holds at least a byte per leaf, so the count is bounded by
// the file size, and a block may not expand past its array, which the writer
// pads to BLOSC_PAD_BYTES (points/StreamCompression.cc, bloscCompress).
void delayed_load(vdb_layout &r, uint32_t num_bytes)
{
    if (num_bytes == 0)
        return;
    const uint64_t blosc_pad = vdb::compression::BLOSC_PAD_BYTES;
    const uint64_t start = r.pos();
    const uint32_t count = r.value<uint32_t>("the delayed-load leaf count");
    if (count > r.size())
        r.fail("at byte %llu, the delayed-load metadata counts %u leaves, more than the file "
               "has bytes", static_cast<unsigned long long>(start), count);
    const uint32_t mask = r.value<uint32_t>("the delayed-load mask size");
    if (mask > 0) {
        if (blosc_uncompressed(r, mask, "the delayed-load mask") > std::max<uint64_t>(count, blosc_pad))
            r.fail("at byte %llu, the delayed-load mask expands past its %u leaves",
                   static_cast<unsigned long long>(start), count);
    } else {
        r.skip(count, "the delayed-load mask");
    }
    const uint32_t sizes = r.value<uint32_t>("the delayed-load sizes' size");
    if (sizes != UINT32_MAX) {
        if (sizes > 0) {
            if (blosc_uncompressed(r, sizes, "the delayed-load sizes") >
                std::max<uint64_t>(uint64_t(count) * 8, blosc_pad))
                r.fail("at byte %llu, the delayed-load sizes expand past their %u leaves",
                       static_cast<unsigned long long>(start), count);
        } else {
            r.skip(uint64_t(count) * 8, "the delayed-load sizes");
        }
    }
    // What OpenVDB counts as read ("total": 12 bytes of header plus the two
    // blocks, in 32 bits), and the rest up to numBytes, which it skips.
    const uint32_t total = static_cast<uint32_t>(r.pos() - start);
    if (total < num_bytes)
        r.skip(num_bytes - total, "the delayed-load metadata");
}

// MetaMap::readMeta: a count, then name, type name and a sized value each.
// Returns the int64 "file_mem_bytes" if there is one (else 0).
uint64_t meta_map(vdb_layout &r)
{
    uint64_t mem_bytes = 0;
    const uint32_t count = r.value<uint32_t>("the metadata count");
    // Each item takes at least 12 bytes (two empty strings and a size).
    if (count > (r.size() - r.pos()) / 12)
        r.fail("at byte %llu, %u metadata items do not fit in the rest of the file",
               static_cast<unsigned long long>(r.pos() - 4), count);
    for (uint32_t i = 0; i < count; ++i) {
        const std::string name = r.string("a metadata name");
        const std::string type = r.string("a metadata type name");
        const uint32_t n = r.value<uint32_t>("a metadata value");
        if (type == vdb::io::DelayedLoadMetadata::staticTypeName()) {
            delayed_load(r, n);
        } else if (type == vdb::StringMetadata::staticTypeName() ||
                   !vdb::Metadata::isRegisteredType(type)) {
            r.skip(n, "a metadata value"); // StringMetadata, UnknownMetadata: n bytes
        } else {
            // A fixed-size value: OpenVDB reads its own size, whatever n says.
            const vdb::Index32 sz = vdb::Metadata::createMetadata(type)->size();
            if (name == vdb::GridBase::META_FILE_MEM_BYTES &&
                type == vdb::Int64Metadata::staticTypeName()) {
                mem_bytes = static_cast<uint64_t>(std::max<int64_t>(0, r.value<int64_t>("a metadata value")));
            } else {
                r.skip(sz, "a metadata value");
            }
        }
    }
    return mem_bytes;
}

// The whole walk; returns the sum of the grids' file_mem_bytes.
uint64_t walk_vdb(vdb_layout &r)
{
    if (r.value<int64_t>("the magic number") != vdb::OPENVDB_MAGIC)
        r.fail("not a VDB file (no VDB magic number)");
    uint32_t version = r.value<uint32_t>("the format version");
    if (version < 211) { // Archive::readHeader: major, minor, patch
        const uint32_t minor = r.value<uint32_t>("the format version");
        const uint32_t patch = r.value<uint32_t>("the format version");
        version = 100 * version + 10 * minor + patch;
    }
    if (version >= 211)
        r.skip(8, "the library version");
    bool offsets = true;
    if (version >= 212)
        offsets = r.value<char>("the grid offsets flag") != 0;
    if (version >= vdb::OPENVDB_FILE_VERSION_SELECTIVE_COMPRESSION &&
        version < vdb::OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION)
        r.skip(1, "the compression flag");
    if (version >= vdb::OPENVDB_FILE_VERSION_BOOST_UUID) {
        for (int i = 0; i < 16; ++i) {
            for (int d = 0; d < 2; ++d)
                if (!std::isxdigit(r.word_char()))
                    r.fail("at byte %llu: the header's uuid is not hexadecimal",
                           static_cast<unsigned long long>(r.pos() - 1));
            if ((i == 3 || i == 5 || i == 7 || i == 9) && r.word_char() != '-')
                r.fail("at byte %llu: the header's uuid lacks a '-'",
                       static_cast<unsigned long long>(r.pos() - 1));
        }
    } else {
        r.skip(16, "the header's uuid");
    }
    meta_map(r);
    const int32_t grids = r.value<int32_t>("the grid count");
    // A descriptor takes at least 32 bytes (two empty strings, three offsets).
    if (grids < 0 || static_cast<uint64_t>(grids) > (r.size() - r.pos()) / 32)
        r.fail("at byte %llu, a count of %d grids does not fit in the rest of the file",
               static_cast<unsigned long long>(r.pos() - 4), grids);
    uint64_t mem = 0;
    for (int32_t g = 0; g < grids; ++g) {
        r.string("a grid name");
        std::string type = r.string("a grid type name");
        const std::string half = "_HalfFloat"; // GridDescriptor.cc's HALF_FLOAT_TYPENAME_SUFFIX
        if (type.size() >= half.size() && type.compare(type.size() - half.size(), half.size(), half) == 0)
            type.erase(type.size() - half.size());
        bool instance = false;
        if (version >= vdb::OPENVDB_FILE_VERSION_GRID_INSTANCING)
            instance = !r.string("a grid's instance parent name").empty();
        if (!vdb::GridBase::isRegistered(type))
            return mem; // OpenVDB refuses it here, before any grid data
        r.skip(16, "the grid offsets");
        const int64_t end = r.value<int64_t>("the grid offsets");
        if (version >= vdb::OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION)
            r.skip(4, "the grid's compression flags");
        const uint64_t m = meta_map(r);
        if (!instance)
            mem = mem + m < mem ? UINT64_MAX : mem + m;
        if (version >= vdb::OPENVDB_FILE_VERSION_GRID_INSTANCING)
            r.string("the grid's transform type");
        // Next: the tree, which only OpenVDB reads; the next grid starts at
        // the end offset.
        if (!offsets)
            break;
        if (end < 0 || static_cast<uint64_t>(end) < r.pos() || static_cast<uint64_t>(end) > r.size())
            r.fail("grid %d: its end offset %lld lies outside the file (%llu bytes)", g,
                   static_cast<long long>(end), static_cast<unsigned long long>(r.size()));
        r.seek(static_cast<uint64_t>(end));
    }
    return mem;
}

} // namespace

// BG_OK if the layout before the trees fits the file and the grids' declared
// in-memory size fits BUMPGRAD_MAX_MB; else BG_ERR_FORMAT naming the file.
static bg_status check_vdb_layout(const char *path, char *err, size_t errlen)
{
    init_vdb();
    FILE *f = std::fopen(path, "rb");
    if (!f) {
        bg_io_set_error(err, errlen, "'%s': cannot open (%s)", path, std::strerror(errno));
        return BG_ERR_IO;
    }
    struct stat st;
    if (fstat(fileno(f), &st) != 0 || st.st_size < 0) {
        std::fclose(f);
        bg_io_set_error(err, errlen, "'%s': cannot stat (%s)", path, std::strerror(errno));
        return BG_ERR_IO;
    }
    vdb_layout r(f, static_cast<uint64_t>(st.st_size));
    uint64_t mem = 0;
    try {
        mem = walk_vdb(r);
    } catch (const vdb_layout_error &e) {
        std::fclose(f);
        bg_io_set_error(err, errlen, "'%s': corrupt VDB file: %s", path, e.msg.c_str());
        return BG_ERR_FORMAT;
    } catch (const std::exception &e) { // OpenVDB's registry (bad_alloc, lookups)
        std::fclose(f);
        bg_io_set_error(err, errlen, "'%s': not a readable VDB file (%s)", path, e.what());
        return BG_ERR_FORMAT;
    }
    std::fclose(f);
    char cap[1024];
    if (bg_io_check_alloc(static_cast<double>(mem), "reading its grids (their file_mem_bytes)",
                          cap, sizeof cap) != BG_OK) {
        bg_io_set_error(err, errlen, "'%s': %s", path, cap);
        return BG_ERR_FORMAT;
    }
    return BG_OK;
}

// OpenVDB 10 trusts the chunk lengths inside compressed streams: some corrupt
// files overflow its heap (glibc then aborts) instead of throwing. So the file
// is read once in a child process first; if that child dies of a signal, the
// file is reported as corrupt here instead of taking the command down. The
// child is given 60 s; the parent then reads the file for real. A clean error
// of the child (its status, then its message) comes back through a pipe, so
// that the parent does not read a corrupt file a second time only to say so:
// a tree that asks for 1.9 GB before failing at the end of the file cost that
// twice (tests/fuzz/crashes/vdb-tree-1.9GB-read-twice).
static bg_status probe_in_child(const char *path, const char *grid_name, char *err, size_t errlen)
{
    std::fflush(nullptr);
    const pid_t parent = getpid();
    const unsigned timeout = bg_io_child_timeout();
    // Non-blocking: the child writes its message once, before it exits, and
    // the parent reads only after that; another child forked meanwhile (a
    // mesh import on another thread) may hold the write end open.
    int msg[2] = {-1, -1};
    if (::pipe2(msg, O_CLOEXEC | O_NONBLOCK) != 0)
        msg[0] = msg[1] = -1; // the parent then reproduces the error itself
    pid_t pid = fork();
    if (pid < 0) {
        if (msg[0] >= 0) {
            ::close(msg[0]);
            ::close(msg[1]);
        }
        return BG_OK; // cannot probe: fall back to reading in-process
    }
    if (pid == 0) {
        // A fuzzed 153 KB file once cost 2 GB here: the same address-space cap
        // as the mesh import child, a time-out, and death with the parent.
        bg_io_child_limits(parent, bg_io_child_memory_cap(path, "BUMPGRAD_VDB_MAX_MB"), timeout);
        // The parent prints the one message, and standard output may be the
        // command's data ("-o -"): blosc prints "Error allocating memory!"
        // to stdout when the cap stops it.
        int fd = ::open("/dev/null", O_WRONLY);
        if (fd >= 0) {
            ::dup2(fd, 1);
            ::dup2(fd, 2);
        }
        bg_vdb_height *h = nullptr;
        char e[512] = "";
        bg_status s;
        try {
            s = open_impl(path, grid_name, &h, e, sizeof e);
        } catch (...) {
            s = BG_ERR_FORMAT;
        }
        // A clean error goes to the parent (under PIPE_BUF: one write that
        // cannot block); running out of the cap is never retried there.
        if (s != BG_OK && s != BG_ERR_OUT_OF_MEMORY && msg[1] >= 0 && e[0]) {
            char buf[1 + sizeof e];
            buf[0] = static_cast<char>(s);
            const size_t n = std::strlen(e);
            std::memcpy(buf + 1, e, n);
            (void)bg_io_write_all(msg[1], buf, 1 + n);
        }
        ::_exit(s == BG_OK ? 0 : s == BG_ERR_OUT_OF_MEMORY ? BG_IO_CHILD_OVER_CAP : 3);
    }
    if (msg[1] >= 0)
        ::close(msg[1]);
    // The read end, closed on every return below.
    struct fd_closer {
        int fd;
        ~fd_closer()
        {
            if (fd >= 0)
                ::close(fd);
        }
    } reply{msg[0]};
    // The child's own alarm ends it after `timeout` s; 1 s later it is killed.
    // The status stays the child's (killed by SIGKILL): a time-out must never
    // fall through to reading the file in-process, without limits.
    int status = 0;
    if (bg_io_wait_child(pid, 1000L * static_cast<long>(timeout) + 1000L, &status) < 0)
        return BG_OK;
    if (WIFSIGNALED(status) && (WTERMSIG(status) == SIGALRM || WTERMSIG(status) == SIGKILL)) {
        bg_io_set_error(err, errlen,
                        "'%s': reading the VDB file took over %u s; giving up (set "
                        "BUMPGRAD_CHILD_TIMEOUT to allow more)", path, timeout);
        return BG_ERR_FORMAT;
    }
    if (WIFSIGNALED(status)) {
        // Also what running into the cap looks like when a library does not
        // check its malloc (blosc: "Error allocating memory!", then SIGSEGV).
        bg_io_set_error(err, errlen,
                        "'%s': corrupt VDB file, or over the probe's memory cap (OpenVDB crashed "
                        "reading it, signal %d; BUMPGRAD_VDB_MAX_MB sets the cap)",
                        path, WTERMSIG(status));
        return BG_ERR_FORMAT;
    }
    if (WIFEXITED(status) && WEXITSTATUS(status) == BG_IO_CHILD_OVER_CAP) {
        bg_io_set_error(err, errlen,
                        "'%s': reading the VDB file needs more memory than a file of this size "
                        "should (corrupt counts?); set BUMPGRAD_VDB_MAX_MB to allow more", path);
        return BG_ERR_FORMAT;
    }
    // 0: the file reads; 3: a clean error, with the child's message, or which
    // the parent reproduces if none came. Any other status (an abort in a
    // library, an allocator giving up) is a failed probe, never a reason to
    // read the file in-process.
    if (!WIFEXITED(status) || (WEXITSTATUS(status) != 0 && WEXITSTATUS(status) != 3)) {
        bg_io_set_error(err, errlen, "'%s': corrupt VDB file (reading it failed with status %d)",
                        path, WIFEXITED(status) ? WEXITSTATUS(status) : -1);
        return BG_ERR_FORMAT;
    }
    if (WEXITSTATUS(status) == 3 && reply.fd >= 0) {
        char buf[513];
        const size_t n = bg_io_read_all(reply.fd, buf, sizeof buf - 1);
        const bg_status s = n > 1 ? static_cast<bg_status>(static_cast<unsigned char>(buf[0]))
                                  : BG_OK;
        if (s == BG_ERR_IO || s == BG_ERR_FORMAT) {
            buf[n] = '\0';
            bg_io_set_error(err, errlen, "%s", buf + 1);
            return s;
        }
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
    // Lengths and declared sizes first, before OpenVDB allocates by them.
    st = check_vdb_layout(path, err, errlen);
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

/* ---- merge ----------------------------------------------------------------- */

// One brick's grids, read as the height reader reads a file: the layout walk
// and the child probe first, then a stream with exceptions on.
static bg_status read_brick(const char *path, vdb::GridPtrVecPtr *grids, char *err, size_t errlen)
{
    bg_status st = check_vdb_layout(path, err, errlen);
    if (st != BG_OK)
        return st;
    if ((st = probe_in_child(path, "height", err, errlen)) != BG_OK)
        return st;
    char what[1024];
    switch (read_grid_stream(path, grids, what, sizeof what)) {
    case stream_read::ok:
        return BG_OK;
    case stream_read::cannot_open:
        bg_io_set_error(err, errlen, "'%s': cannot open", path);
        return BG_ERR_IO;
    case stream_read::no_memory:
        bg_io_set_error(err, errlen, "'%s': out of memory reading the grids", path);
        return BG_ERR_OUT_OF_MEMORY;
    case stream_read::past_end:
    case stream_read::corrupt:
        break;
    }
    bg_io_set_error(err, errlen, "'%s': truncated or corrupt VDB file", path);
    return BG_ERR_FORMAT;
}

template <typename GridT>
static bool merge_into(vdb::GridBase::Ptr dst, vdb::GridBase::Ptr src)
{
    auto d = vdb::gridPtrCast<GridT>(dst);
    auto s = vdb::gridPtrCast<GridT>(src);
    if (!d || !s)
        return false;
    // OpenVDB's own tree merge: the brick's active voxels (and tiles) move
    // into the result; bricks are disjoint, so nothing is overwritten (the
    // caller checks the voxel counts add up).
    d->tree().merge(s->tree(), vdb::MERGE_ACTIVE_STATES);
    return true;
}

bg_status bg_vdb_merge(const char *const *inputs, size_t n, const char *output, char *err,
                       size_t errlen)
{
    bg_io_set_error(err, errlen, "%s", "");
    if (!inputs || !output || n == 0) {
        bg_io_set_error(err, errlen, "bg_vdb_merge: no input or no output");
        return BG_ERR_NULL_POINTER;
    }
    init_vdb();
    vdb::GridPtrVecPtr base;
    std::vector<uint64_t> expect; // active voxels per grid, summed over the bricks
    for (size_t b = 0; b < n; ++b) {
        if (!inputs[b]) {
            bg_io_set_error(err, errlen, "bg_vdb_merge: input %zu is NULL", b);
            return BG_ERR_NULL_POINTER;
        }
        vdb::GridPtrVecPtr grids;
        bg_status st = read_brick(inputs[b], &grids, err, errlen);
        if (st != BG_OK)
            return st;
        if (!base) {
            base = grids;
            for (auto &g : *base)
                expect.push_back(static_cast<uint64_t>(g->activeVoxelCount()));
            continue;
        }
        st = bg_io_guard("cannot merge '" + std::string(inputs[b]) + "'", "out of memory", "",
                         BG_ERR_FORMAT, err, errlen, [&] {
            if (grids->size() != base->size())
                throw std::runtime_error("it has " + std::to_string(grids->size()) +
                                         " grids, the first brick " +
                                         std::to_string(base->size()));
            for (size_t g = 0; g < base->size(); ++g) {
                auto &d = (*base)[g];
                auto s = vdb::findGridByName(*grids, d->getName());
                if (!s || s->type() != d->type())
                    throw std::runtime_error("no " + d->type() + " grid '" + d->getName() +
                                             "' as in '" + inputs[0] + "'");
                if (s->transform() != d->transform())
                    throw std::runtime_error("grid '" + d->getName() +
                                             "' has another transform (voxel size or origin)"
                                             " than in '" + std::string(inputs[0]) + "'");
                auto ms = (*s)["bumpgrad:height"], md = (*d)["bumpgrad:height"];
                if ((ms ? ms->str() : "") != (md ? md->str() : ""))
                    throw std::runtime_error("grid '" + d->getName() +
                                             "' was baked with other height parameters (" +
                                             (ms ? ms->str() : "none") + ") than in '" +
                                             inputs[0] + "' (" + (md ? md->str() : "none") + ")");
                expect[g] += static_cast<uint64_t>(s->activeVoxelCount());
                if (!merge_into<vdb::FloatGrid>(d, s) && !merge_into<vdb::Vec3SGrid>(d, s))
                    throw std::runtime_error("grid '" + d->getName() + "' of type " + d->type() +
                                             " cannot be merged (float and vec3s grids only)");
            }
            return BG_OK;
        }, [] {});
        if (st != BG_OK)
            return st;
    }
    for (size_t g = 0; g < base->size(); ++g)
        if (static_cast<uint64_t>((*base)[g]->activeVoxelCount()) != expect[g]) {
            bg_io_set_error(err, errlen,
                            "the bricks overlap: grid '%s' has %llu active voxels merged, %llu "
                            "in the bricks together",
                            (*base)[g]->getName().c_str(),
                            (unsigned long long)(*base)[g]->activeVoxelCount(),
                            (unsigned long long)expect[g]);
            return BG_ERR_INVALID_ARGUMENT;
        }
    return write_grids(output, [&](vdb::GridCPtrVec &grids) {
        grids.assign(base->begin(), base->end());
    }, err, errlen);
}
