// SPDX-License-Identifier: MIT
// Image I/O of the tools over OpenImageIO 2.4 (include/bumpgrad/image.h).
// Everything that can throw stays inside this file: every extern "C" entry
// point catches and turns exceptions into a status, since a C++ exception
// crossing into the C command line would be undefined behaviour.
#include "bumpgrad/image.h"

#include <cctype>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <OpenImageIO/filesystem.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include <pthread.h>
#include <signal.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "io_util.h"

using namespace OIIO;


// "-" names the standard streams (as it does for the CSV and PLY tools).
static bool is_stream(const char *path) { return std::strcmp(path, "-") == 0; }

// The name an image goes by in messages.
static std::string display_name(const char *path, bool output)
{
    if (is_stream(path))
        return output ? "<stdout>" : "<stdin>";
    return std::string("'") + path + "'";
}

// Standard input, read to its end into memory (an image reader needs to seek).
// The buffer is checked against the one allocation cap (BUMPGRAD_MAX_MB) before
// it grows, so an endless pipe is refused at the cap instead of filling memory.
static bg_status read_stdin(std::vector<unsigned char> *buf, char *err, size_t errlen)
{
    size_t used = 0;
    for (;;) {
        if (used == buf->size()) {
            const size_t want = std::max<size_t>(size_t(1) << 16, 2 * buf->size());
            char cap_err[1024];
            const bg_status cs = bg_io_check_alloc(static_cast<double>(want),
                                                   "reading an image from standard input",
                                                   cap_err, sizeof cap_err);
            if (cs != BG_OK) {
                const size_t cap = bg_io_memory_cap();
                if (used >= cap || cs != BG_ERR_INVALID_ARGUMENT) {
                    bg_io_set_error(err, errlen, "<stdin>: more than %zu bytes: %s", used,
                                    cap_err);
                    return BG_ERR_INVALID_ARGUMENT;
                }
                buf->resize(cap); // the last growth stops at the cap itself
            } else {
                buf->resize(want);
            }
        }
        const size_t want = buf->size() - used;
        const size_t k = bg_io_read_all(0, buf->data() + used, want);
        used += k;
        if (k < want && errno != 0) {
            bg_io_set_error(err, errlen, "<stdin>: %s", std::strerror(errno));
            return BG_ERR_IO;
        }
        if (k < want)
            break; // end of input
    }
    buf->resize(used);
    if (used == 0) {
        bg_io_set_error(err, errlen, "<stdin>: empty input, no image in it");
        return BG_ERR_FORMAT;
    }
    return BG_OK;
}

// Formats OpenImageIO lists that must not be guessed for unknown content:
// "null" opens any name without reading it, "term" is an output only.
static bool guessable(const std::string &fmt) { return fmt != "null" && fmt != "term"; }

// An ImageInput for `format` (a format name or extension), or an error naming it.
// For the stream, only readers that take an IOProxy (OpenImageIO 2.4: PNG, JPEG,
// TIFF, OpenEXR, HDR, PNM, TGA, BMP, GIF, WebP, DPX, ...; not e.g. SGI, FITS, RLA).
static bg_status create_input(const char *format, bool stream, std::unique_ptr<ImageInput> *in,
                              char *err, size_t errlen)
{
    *in = ImageInput::create(format);
    if (!*in) {
        (void)OIIO::geterror();
        bg_io_set_error(err, errlen, "unknown image format '%s' (use png, exr, tif, ...)", format);
        return BG_ERR_INVALID_ARGUMENT;
    }
    if (stream && !(*in)->supports("ioproxy")) {
        bg_io_set_error(err, errlen,
                        "<stdin>: OpenImageIO 2.4 cannot read the '%s' format from a stream; "
                        "read it from a file instead", (*in)->format_name());
        in->reset();
        return BG_ERR_INVALID_ARGUMENT;
    }
    return BG_OK;
}

// Opens standard input's bytes (`mem`) as `format`, or with format NULL as the
// first stream-capable reader that accepts the content (each checks its magic).
static bg_status open_stream(const std::vector<unsigned char> &mem, const char *format,
                             std::unique_ptr<Filesystem::IOMemReader> *proxy,
                             std::unique_ptr<ImageInput> *in, char *err, size_t errlen)
{
    std::vector<std::string> formats;
    if (format) {
        formats.emplace_back(format);
    } else {
        std::string list;
        OIIO::getattribute("input_format_list", list);
        for (auto f : Strutil::splitsv(list, ","))
            if (guessable(std::string(f)))
                formats.emplace_back(f);
    }
    std::string why;
    for (const std::string &f : formats) {
        std::unique_ptr<ImageInput> cand;
        bg_status st = create_input(f.c_str(), true, &cand, err, errlen);
        if (st != BG_OK) {
            if (format)
                return st;
            continue; // a reader without IOProxy support: not a candidate
        }
        auto p = std::make_unique<Filesystem::IOMemReader>(mem.data(), mem.size());
        cand->set_ioproxy(p.get());
        ImageSpec spec;
        if (cand->open("<stdin>", spec)) {
            *proxy = std::move(p);
            *in = std::move(cand);
            return BG_OK;
        }
        if (format)
            why = cand->geterror();
    }
    (void)OIIO::geterror();
    if (format)
        bg_io_set_error(err, errlen, "<stdin>: not a readable %s image (%s)", format,
                        why.empty() ? "wrong format" : why.c_str());
    else
        bg_io_set_error(err, errlen,
                        "<stdin>: not an image in a format that can be read from a stream "
                        "(PNG, JPEG, TIFF, OpenEXR, HDR, PNM, TGA, BMP, ...)");
    return BG_ERR_FORMAT;
}

// OpenImageIO 2.4's BMP reader decodes RLE8/RLE4 data inside open(), before
// any spec can be checked, into a zeroed width x height byte buffer: a 70-byte
// BMP declaring 247 x 8389636 pixels made that 2 GB (6 s, 2.1 GB resident)
// under a 64 MiB cap (tests/fuzz/regress/image/image-bmp-rle8-2GB). It also
// takes RLE data at any bit depth and then indexes its palette with it, far
// out of bounds (SIGSEGV, in oiiotool too), when the header pairs RLE8 with
// other than 8 bits per pixel or RLE4 with other than 4, which the format does
// not allow (image-bmp-rle8-16bpp-segv). So a BMP header, recognised by its
// content (OpenImageIO tries every reader on a name it does not know), is
// checked before OpenImageIO sees the file. `h` holds the first n bytes.
static bg_status check_bmp_header(const unsigned char *h, size_t n, const std::string &name,
                                  char *err, size_t errlen)
{
    if (n < 34 || h[0] != 'B' || h[1] != 'M')
        return BG_OK;
    auto u32 = [h](size_t o) {
        return static_cast<uint32_t>(h[o]) | static_cast<uint32_t>(h[o + 1]) << 8 |
               static_cast<uint32_t>(h[o + 2]) << 16 | static_cast<uint32_t>(h[o + 3]) << 24;
    };
    const uint32_t compression = u32(30);
    if (u32(14) < 40 || (compression != 1 && compression != 2))
        return BG_OK; // no compression field (OS/2 header), or not RLE
    const unsigned bits = static_cast<unsigned>(h[28]) | static_cast<unsigned>(h[29]) << 8;
    const unsigned rle = compression == 1 ? 8 : 4;
    if (bits != rle) {
        bg_io_set_error(err, errlen, "%s: corrupt BMP (RLE%u compression with %u bits per pixel)",
                        name.c_str(), rle, bits);
        return BG_ERR_FORMAT;
    }
    const double w = std::fabs(static_cast<double>(static_cast<int32_t>(u32(18))));
    const double hh = std::fabs(static_cast<double>(static_cast<int32_t>(u32(22))));
    char cap_err[1024];
    if (bg_io_check_alloc(w * hh, "decoding its RLE data", cap_err, sizeof cap_err) != BG_OK) {
        bg_io_set_error(err, errlen, "%s: %.0fx%.0f RLE%u BMP: %s", name.c_str(), w, hh, rle,
                        cap_err);
        return BG_ERR_FORMAT;
    }
    return BG_OK;
}

static bg_status read_impl(const char *path, const char *format, bg_image *out, char *err,
                           size_t errlen)
{
    const bool stream = is_stream(path);
    const std::string name = display_name(path, false);
    std::vector<unsigned char> mem;
    std::unique_ptr<Filesystem::IOMemReader> proxy; // outlives `in`, which reads through it
    std::unique_ptr<ImageInput> in;
    bg_status st;
    if (stream) {
        st = read_stdin(&mem, err, errlen);
        if (st == BG_OK)
            st = check_bmp_header(mem.data(), mem.size(), name, err, errlen);
        if (st == BG_OK)
            st = open_stream(mem, format, &proxy, &in, err, errlen);
        if (st != BG_OK)
            return st;
    } else {
        // Tell "missing / unreadable" (an I/O problem) from "not an image /
        // corrupt" (a format problem) before OpenImageIO does: its open()
        // reports both as "could not open".
        st = bg_io_check_readable(path, nullptr, err, errlen);
        if (st != BG_OK)
            return st;
        unsigned char head[34];
        size_t got = 0;
        if (FILE *f = std::fopen(path, "rb")) {
            got = std::fread(head, 1, sizeof head, f);
            std::fclose(f);
        }
        st = check_bmp_header(head, got, name, err, errlen);
        if (st != BG_OK)
            return st;
        if (format) {
            st = create_input(format, false, &in, err, errlen);
            if (st != BG_OK)
                return st;
            ImageSpec spec;
            if (!in->open(path, spec))
                in.reset();
        } else {
            in = ImageInput::open(path);
        }
        if (!in) {
            std::string msg = OIIO::geterror();
            bg_io_set_error(err, errlen, "%s: not a readable image (%s)", name.c_str(),
                            msg.empty() ? "unknown format" : msg.c_str());
            return BG_ERR_FORMAT;
        }
    }
    const ImageSpec &spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.depth > 1) {
        bg_io_set_error(err, errlen, "%s: unsupported image shape %dx%dx%d with %d channels",
                        name.c_str(), spec.width, spec.height, spec.depth, spec.nchannels);
        return BG_ERR_FORMAT;
    }
    if (spec.tile_width < 0 || spec.tile_height < 0 || spec.tile_depth < 0) {
        bg_io_set_error(err, errlen, "%s: unsupported tile size %dx%dx%d", name.c_str(),
                        spec.tile_width, spec.tile_height, spec.tile_depth);
        return BG_ERR_FORMAT;
    }
    // The declared size decides the allocation: check it against the one cap
    // first (a 442-byte TGA may declare 28018 x 65535 pixels). The float image
    // and, for most formats, a native-format buffer of the same order. A tiled
    // file is read a row of tiles at a time, each tile at its declared size even
    // where it overhangs the image: OpenImageIO holds the row in the native
    // format, converts through float tiles, and the format's reader decodes
    // into a tile of its own. A 4x4 TIFF declaring 32768 x 32768 tiles cost
    // 15.8 GB that way under a 64 MiB cap
    // (tests/fuzz/regress/image/image-tif-4x4-tiles-32768).
    const double pixels = static_cast<double>(spec.width) * spec.height;
    const double float_pixel = static_cast<double>(spec.nchannels) * sizeof(float);
    double need = 2.0 * pixels * float_pixel;
    if (spec.tile_width > 0) {
        const double tiles_x = std::ceil(static_cast<double>(spec.width) / spec.tile_width);
        const double tile = static_cast<double>(spec.tile_width) * std::max(spec.tile_height, 1) *
                            std::max(spec.tile_depth, 1);
        need = pixels * float_pixel +
               tiles_x * tile * (2.0 * static_cast<double>(spec.pixel_bytes(true)) + float_pixel);
    }
    char cap_err[1024];
    if (bg_io_check_alloc(need, "reading the image", cap_err, sizeof cap_err) != BG_OK) {
        if (spec.tile_width > 0)
            bg_io_set_error(err, errlen, "%s: %dx%d with %d channels in %dx%d tiles: %s",
                            name.c_str(), spec.width, spec.height, spec.nchannels,
                            spec.tile_width, spec.tile_height, cap_err);
        else
            bg_io_set_error(err, errlen, "%s: %dx%d with %d channels: %s", name.c_str(),
                            spec.width, spec.height, spec.nchannels, cap_err);
        return BG_ERR_FORMAT;
    }
    bg_image img;
    st = bg_image_alloc(&img, spec.width, spec.height, spec.nchannels);
    if (st != BG_OK) {
        bg_io_set_error(err, errlen, "%s: %dx%d image with %d channels is too large",
                        name.c_str(), spec.width, spec.height, spec.nchannels);
        return st;
    }
    // Integer formats convert to [0, 1] here (OIIO's normalized conversion).
    if (!in->read_image(0, 0, 0, spec.nchannels, TypeDesc::FLOAT, img.pixels)) {
        std::string msg = in->geterror();
        bg_io_set_error(err, errlen, "%s: corrupt or truncated image (%s)", name.c_str(),
                        msg.empty() ? "read failed" : msg.c_str());
        bg_image_free(&img);
        return BG_ERR_FORMAT;
    }
    in->close();
    *out = img;
    return BG_OK;
}

// Both entry points call this directly: the module's own calls must not go
// through whichever bg_image_read_as the process resolves first (a loader's).
static bg_status read_guarded(const char *path, const char *format, bg_image *out, char *err,
                              size_t errlen)
{
    bg_io_set_error(err, errlen, "%s", "");
    if (!path || !out) {
        bg_io_set_error(err, errlen, "bg_image_read: NULL argument");
        return BG_ERR_NULL_POINTER;
    }
    out->width = out->height = out->channels = 0;
    out->pixels = nullptr;
    if (format && !*format)
        format = nullptr;
    return bg_io_guard(display_name(path, false), "out of memory", "", BG_ERR_FORMAT, err, errlen,
                       [&] { return read_impl(path, format, out, err, errlen); });
}

// A format as a user writes it ("exr", ".exr", "EXR") as OpenImageIO names it:
// without the dot, in lower case.
static std::string format_key(const char *format)
{
    std::string f(format + (format[0] == '.'));
    for (char &c : f)
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return f;
}

bg_status bg_image_read_as(const char *path, const char *format, bg_image *out, char *err,
                           size_t errlen)
{
    if (!format)
        return read_guarded(path, nullptr, out, err, errlen);
    const std::string key = format_key(format);
    return read_guarded(path, key.c_str(), out, err, errlen);
}

bg_status bg_image_read(const char *path, bg_image *out, char *err, size_t errlen)
{
    return read_guarded(path, nullptr, out, err, errlen);
}

// IEC 61966-2-1 encoding of a linear value; NaN maps to 0 so that a display
// image never carries an undefined pixel.
static float srgb_encode(float v)
{
    if (!(v > 0.0f))
        return 0.0f;
    if (v >= 1.0f)
        return 1.0f;
    return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

static TypeDesc pixel_typedesc(bg_pixel_type t)
{
    switch (t) {
    case BG_PIXEL_U8: return TypeDesc::UINT8;
    case BG_PIXEL_U16: return TypeDesc::UINT16;
    case BG_PIXEL_HALF: return TypeDesc::HALF;
    case BG_PIXEL_F32: return TypeDesc::FLOAT;
    }
    return TypeDesc::UNKNOWN;
}

// Some writers (libpng through OpenImageIO's PNG plugin) ignore a failed
// fwrite: on a full disk the file is short and close() still succeeds. So the
// finished temporary is read back in full before it may replace anything.
static bool read_back_ok(const std::string &tmp, const bg_image *img, std::string *why)
{
    auto in = ImageInput::open(tmp);
    if (!in) {
        *why = OIIO::geterror();
        return false;
    }
    const ImageSpec &spec = in->spec();
    if (spec.width != img->width || spec.height != img->height ||
        spec.nchannels != img->channels) {
        *why = "the file read back has another size";
        return false;
    }
    std::vector<float> pixels(static_cast<size_t>(spec.width) * spec.height * spec.nchannels);
    bool ok = in->read_image(0, 0, 0, spec.nchannels, TypeDesc::FLOAT, pixels.data());
    if (!ok)
        *why = in->geterror();
    in->close();
    return ok;
}

// Standard output gets the finished image in one piece. SIGPIPE is blocked
// for the write, so a reader that went away (`| head -c 10`) is an EPIPE
// error reported like any other, not a process killed by a signal; a SIGPIPE
// the write raised is taken off this thread before the mask is restored.
static bg_status write_stdout(const std::vector<unsigned char> &buf, char *err, size_t errlen)
{
    std::fflush(stdout); // whatever the caller printed before comes first
    sigset_t pipe_set, old;
    sigemptyset(&pipe_set);
    sigaddset(&pipe_set, SIGPIPE);
    pthread_sigmask(SIG_BLOCK, &pipe_set, &old);
    const size_t done = bg_io_write_all(1, buf.data(), buf.size());
    int e = done < buf.size() ? (errno ? errno : EIO) : 0;
    // A regular file as standard output: make a full disk show up here.
    struct stat st;
    if (!e && ::fstat(1, &st) == 0 && S_ISREG(st.st_mode) && ::fsync(1) != 0 && errno != EINVAL)
        e = errno;
    if (e == EPIPE && !sigismember(&old, SIGPIPE)) {
        const struct timespec zero = {0, 0};
        while (sigtimedwait(&pipe_set, nullptr, &zero) > 0) {
        }
    }
    pthread_sigmask(SIG_SETMASK, &old, nullptr);
    if (e) {
        bg_io_set_error(err, errlen, "cannot write the image to <stdout> (%s, %zu of %zu bytes "
                        "written)", std::strerror(e), done, buf.size());
        return BG_ERR_IO;
    }
    return BG_OK;
}

// The ImageOutput for `path`: by `format` if given (a format name or
// extension), else by the path's extension; standard output defaults to PNG
// and needs a writer that takes an IOProxy (OpenImageIO 2.4: not SGI, FITS,
// RLA, ICO, HEIF, ...).
static bg_status create_output(const char *path, const char *format,
                               std::unique_ptr<ImageOutput> *out, char *err, size_t errlen)
{
    const bool stream = is_stream(path);
    const char *by = format ? format : stream ? "png" : path;
    *out = ImageOutput::create(by);
    if (!*out) {
        (void)OIIO::geterror();
        if (format)
            bg_io_set_error(err, errlen, "%s: unknown image format '%s' (use png, exr, tif, ...)",
                            display_name(path, true).c_str(), format);
        else
            bg_io_set_error(err, errlen,
                            "'%s': no image format for this file extension "
                            "(use .png, .exr, .tif, ...)",
                            path);
        return BG_ERR_INVALID_ARGUMENT;
    }
    if (stream && !(*out)->supports("ioproxy")) {
        bg_io_set_error(err, errlen,
                        "<stdout>: OpenImageIO 2.4 cannot write the '%s' format to a stream; "
                        "write it to a file, or use png, exr, tif, jpg, hdr, ppm, tga or bmp",
                        (*out)->format_name());
        out->reset();
        return BG_ERR_INVALID_ARGUMENT;
    }
    if (stream && ::isatty(1)) {
        bg_io_set_error(err, errlen, "<stdout> is a terminal: not writing a %s image to it "
                        "(redirect it to a file or a pipe)", (*out)->format_name());
        out->reset();
        return BG_ERR_INVALID_ARGUMENT;
    }
    return BG_OK;
}

static bg_status write_impl(const char *path, const char *format, const bg_image *img,
                            bg_pixel_type type, int srgb, char *err, size_t errlen)
{
    TypeDesc td = pixel_typedesc(type);
    if (td == TypeDesc::UNKNOWN) {
        bg_io_set_error(err, errlen, "%s: unknown pixel type %d", display_name(path, true).c_str(),
                        static_cast<int>(type));
        return BG_ERR_INVALID_ARGUMENT;
    }
    // The writer is chosen before any file is created (an unknown format is
    // refused first); it then writes to the temporary name, which keeps the
    // extension, or to memory for standard output.
    std::unique_ptr<ImageOutput> out;
    bg_status st = create_output(path, format, &out, err, errlen);
    if (st != BG_OK)
        return st;

    const size_t count = static_cast<size_t>(img->width) * static_cast<size_t>(img->height) *
                         static_cast<size_t>(img->channels);
    const float *src = img->pixels;
    std::vector<float> encoded;
    if (srgb) {
        encoded.resize(count);
        const int c = img->channels;
        // Alpha (4th channel of RGBA, 2nd of gray+alpha) stays linear, as PNG defines it.
        const int alpha = (c == 4) ? 3 : (c == 2 ? 1 : -1);
        for (size_t i = 0; i < count; ++i)
            encoded[i] = (static_cast<int>(i % static_cast<size_t>(c)) == alpha)
                             ? src[i]
                             : srgb_encode(src[i]);
        src = encoded.data();
    }

    const bool stream = is_stream(path);
    std::string tmp;
    std::unique_ptr<Filesystem::IOVecOutput> mem;
    if (stream) {
        mem = std::make_unique<Filesystem::IOVecOutput>();
        out->set_ioproxy(mem.get());
        tmp = "<stdout>";
    } else {
        st = bg_io_make_temp(path, &tmp, err, errlen);
        if (st != BG_OK)
            return st;
    }

    ImageSpec spec(img->width, img->height, img->channels, td);
    if (srgb)
        spec.attribute("oiio:ColorSpace", "sRGB");
    else if (td == TypeDesc::HALF || td == TypeDesc::FLOAT)
        spec.attribute("oiio:ColorSpace", "Linear");
    spec.attribute("Software", "bumpgrad " BG_IO_VERSION_STRING);
    if (td == TypeDesc::HALF || td == TypeDesc::FLOAT)
        spec.attribute("compression", "zip");

    bool ok = out->open(tmp, spec);
    if (ok)
        ok = out->write_image(TypeDesc::FLOAT, src);
    if (ok)
        ok = out->close();
    if (!ok) {
        std::string msg = out->geterror();
        out.reset(); // closes the temporary file before it is removed
        bg_io_set_error(err, errlen, "cannot write %s (%s)", display_name(path, true).c_str(),
                        msg.empty() ? "write failed" : msg.c_str());
        if (!stream)
            bg_io_discard_temp(tmp);
        return BG_ERR_IO;
    }
    out.reset();
    // In memory nothing can be short; the bytes go out in one piece.
    if (stream)
        return write_stdout(mem->buffer(), err, errlen);
    std::string why;
    if (!read_back_ok(tmp, img, &why)) {
        bg_io_set_error(err, errlen, "cannot write '%s' (the written file does not read back: %s)",
                        path, why.empty() ? "read failed" : why.c_str());
        bg_io_discard_temp(tmp);
        return BG_ERR_IO;
    }
    return bg_io_commit_temp(tmp, path, err, errlen);
}

static bg_status write_guarded(const char *path, const char *format, const bg_image *img,
                               bg_pixel_type type, int srgb, char *err, size_t errlen)
{
    bg_io_set_error(err, errlen, "%s", "");
    if (!path || !img || !img->pixels) {
        bg_io_set_error(err, errlen, "bg_image_write: NULL argument");
        return BG_ERR_NULL_POINTER;
    }
    const std::string name = display_name(path, true);
    if (img->width <= 0 || img->height <= 0 || img->channels <= 0) {
        bg_io_set_error(err, errlen, "%s: empty image %dx%d with %d channels", name.c_str(),
                        img->width, img->height, img->channels);
        return BG_ERR_INVALID_ARGUMENT;
    }
    if (format && !*format)
        format = nullptr;
    return bg_io_guard("cannot write " + name, "out of memory", "", BG_ERR_IO, err, errlen,
                       [&] { return write_impl(path, format, img, type, srgb, err, errlen); });
}

bg_status bg_image_write_as(const char *path, const char *format, const bg_image *img,
                            bg_pixel_type type, int srgb, char *err, size_t errlen)
{
    if (!format)
        return write_guarded(path, nullptr, img, type, srgb, err, errlen);
    const std::string key = format_key(format);
    return write_guarded(path, key.c_str(), img, type, srgb, err, errlen);
}

bg_status bg_image_write(const char *path, const bg_image *img, bg_pixel_type type, int srgb,
                         char *err, size_t errlen)
{
    return write_guarded(path, nullptr, img, type, srgb, err, errlen);
}

static bg_status draw_text_impl(bg_image *img, int x, int y, const char *text, const float rgb[3],
                                int size, char *err, size_t errlen)
{
    ImageSpec spec(img->width, img->height, img->channels, TypeDesc::FLOAT);
    // Wraps the caller's pixels: render_text composites straight into them.
    ImageBuf buf(spec, img->pixels);
    std::vector<float> color(static_cast<size_t>(img->channels), 1.0f);
    for (int c = 0; c < img->channels && c < 3; ++c)
        color[static_cast<size_t>(c)] = rgb[c];

    // Debian's OpenImageIO has no DroidSans, its built-in default, so name a
    // font that fonts-dejavu-core installs; BUMPGRAD_FONT overrides.
    std::vector<std::string> fonts;
    if (const char *env = std::getenv("BUMPGRAD_FONT"))
        if (*env)
            fonts.emplace_back(env);
    fonts.emplace_back("DejaVuSans");
    fonts.emplace_back("");
    std::string last;
    for (const std::string &f : fonts) {
        if (ImageBufAlgo::render_text(buf, x, y, text, size, f, color, ImageBufAlgo::TextAlignX::Left,
                                      ImageBufAlgo::TextAlignY::Top))
            return BG_OK;
        last = buf.geterror();
    }
    bg_io_set_error(err, errlen, "cannot draw text: no usable font (%s); set BUMPGRAD_FONT",
                    last.empty() ? "unknown error" : last.c_str());
    return BG_ERR_IO;
}

bg_status bg_image_draw_text(bg_image *img, int x, int y, const char *text, const float rgb[3],
                             int size, char *err, size_t errlen)
{
    bg_io_set_error(err, errlen, "%s", "");
    if (!img || !img->pixels || !text || !rgb) {
        bg_io_set_error(err, errlen, "bg_image_draw_text: NULL argument");
        return BG_ERR_NULL_POINTER;
    }
    if (img->width <= 0 || img->height <= 0 || img->channels <= 0 || size <= 0) {
        bg_io_set_error(err, errlen, "bg_image_draw_text: bad image or font size");
        return BG_ERR_INVALID_ARGUMENT;
    }
    return bg_io_guard("cannot draw text", "out of memory", "", BG_ERR_IO, err, errlen,
                       [&] { return draw_text_impl(img, x, y, text, rgb, size, err, errlen); });
}
