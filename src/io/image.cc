// SPDX-License-Identifier: MIT
// Image I/O of the tools over OpenImageIO 2.4 (include/bumpgrad/image.h).
// Everything that can throw stays inside this file: every extern "C" entry
// point catches and turns exceptions into a status, since a C++ exception
// crossing into the C command line would be undefined behaviour.
#include "bumpgrad/image.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "io_util.h"
#include "common/tool.h"

using namespace OIIO;


static bg_status read_impl(const char *path, bg_image *out, char *err, size_t errlen)
{
    // Tell "missing / unreadable" (an I/O problem) from "not an image / corrupt"
    // (a format problem) before OpenImageIO does: its open() reports both as
    // "could not open".
    bg_status st = bg_io_check_readable(path, nullptr, err, errlen);
    if (st != BG_OK)
        return st;

    auto in = ImageInput::open(path);
    if (!in) {
        std::string msg = OIIO::geterror();
        bg_io_set_error(err, errlen, "'%s': not a readable image (%s)", path,
                        msg.empty() ? "unknown format" : msg.c_str());
        return BG_ERR_FORMAT;
    }
    const ImageSpec &spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.depth > 1) {
        bg_io_set_error(err, errlen, "'%s': unsupported image shape %dx%dx%d with %d channels",
                        path, spec.width, spec.height, spec.depth, spec.nchannels);
        return BG_ERR_FORMAT;
    }
    // The declared size decides the allocation: check it against the one cap
    // first (a 442-byte TGA may declare 28018 x 65535 pixels). The float image
    // and, for most formats, a native-format buffer of the same order.
    bgt_err cap_err;
    if (bgt_check_alloc(2.0 * spec.width * spec.height * spec.nchannels * sizeof(float),
                        "reading the image", &cap_err) != BG_OK) {
        bg_io_set_error(err, errlen, "'%s': %dx%d with %d channels: %s", path, spec.width,
                        spec.height, spec.nchannels, cap_err.msg);
        return BG_ERR_FORMAT;
    }
    bg_image img;
    st = bg_image_alloc(&img, spec.width, spec.height, spec.nchannels);
    if (st != BG_OK) {
        bg_io_set_error(err, errlen, "'%s': %dx%d image with %d channels is too large", path,
                        spec.width, spec.height, spec.nchannels);
        return st;
    }
    // Integer formats convert to [0, 1] here (OIIO's normalized conversion).
    if (!in->read_image(0, 0, 0, spec.nchannels, TypeDesc::FLOAT, img.pixels)) {
        std::string msg = in->geterror();
        bg_io_set_error(err, errlen, "'%s': corrupt or truncated image (%s)", path,
                        msg.empty() ? "read failed" : msg.c_str());
        bg_image_free(&img);
        return BG_ERR_FORMAT;
    }
    in->close();
    *out = img;
    return BG_OK;
}

bg_status bg_image_read(const char *path, bg_image *out, char *err, size_t errlen)
{
    bg_io_set_error(err, errlen, "%s", "");
    if (!path || !out) {
        bg_io_set_error(err, errlen, "bg_image_read: NULL argument");
        return BG_ERR_NULL_POINTER;
    }
    out->width = out->height = out->channels = 0;
    out->pixels = nullptr;
    return bg_io_guard("'" + std::string(path) + "'", "out of memory", "", BG_ERR_FORMAT, err,
                       errlen, [&] { return read_impl(path, out, err, errlen); });
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

static bg_status write_impl(const char *path, const bg_image *img, bg_pixel_type type, int srgb,
                            char *err, size_t errlen)
{
    TypeDesc td = pixel_typedesc(type);
    if (td == TypeDesc::UNKNOWN) {
        bg_io_set_error(err, errlen, "'%s': unknown pixel type %d", path, static_cast<int>(type));
        return BG_ERR_INVALID_ARGUMENT;
    }
    // The writer is chosen from the final path's extension, so an unknown
    // extension is refused before any file is created; it then writes to the
    // temporary name, which keeps that extension.
    auto out = ImageOutput::create(path);
    if (!out) {
        (void)OIIO::geterror();
        bg_io_set_error(err, errlen,
                        "'%s': no image format for this file extension "
                        "(use .png, .exr, .tif, ...)",
                        path);
        return BG_ERR_INVALID_ARGUMENT;
    }

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

    std::string tmp;
    bg_status st = bg_io_make_temp(path, &tmp, err, errlen);
    if (st != BG_OK)
        return st;

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
        bg_io_set_error(err, errlen, "cannot write '%s' (%s)", path,
                        msg.empty() ? "write failed" : msg.c_str());
        bg_io_discard_temp(tmp);
        return BG_ERR_IO;
    }
    out.reset();
    std::string why;
    if (!read_back_ok(tmp, img, &why)) {
        bg_io_set_error(err, errlen, "cannot write '%s' (the written file does not read back: %s)",
                        path, why.empty() ? "read failed" : why.c_str());
        bg_io_discard_temp(tmp);
        return BG_ERR_IO;
    }
    return bg_io_commit_temp(tmp, path, err, errlen);
}

bg_status bg_image_write(const char *path, const bg_image *img, bg_pixel_type type, int srgb,
                         char *err, size_t errlen)
{
    bg_io_set_error(err, errlen, "%s", "");
    if (!path || !img || !img->pixels) {
        bg_io_set_error(err, errlen, "bg_image_write: NULL argument");
        return BG_ERR_NULL_POINTER;
    }
    if (img->width <= 0 || img->height <= 0 || img->channels <= 0) {
        bg_io_set_error(err, errlen, "'%s': empty image %dx%d with %d channels", path,
                        img->width, img->height, img->channels);
        return BG_ERR_INVALID_ARGUMENT;
    }
    return bg_io_guard("cannot write '" + std::string(path) + "'", "out of memory", "", BG_ERR_IO,
                       err, errlen, [&] { return write_impl(path, img, type, srgb, err, errlen); });
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
