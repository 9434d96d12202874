/* SPDX-License-Identifier: MIT */
/* Where a mesh material's texture is on this machine (mesh_texpath.c). A
 * mesh exported elsewhere often names its textures by paths of that machine
 * (C:\Users\me\proj\tex\albedo.png, /home/other/tex/albedo.png): as Blender's
 * "find missing files" and most OBJ/glTF viewers do, a texture that is not
 * where the file says is looked for by its base name next to the mesh.
 * libc only. */
#ifndef BUMPGRAD_TOOLS_MESH_TEXPATH_H
#define BUMPGRAD_TOOLS_MESH_TEXPATH_H

#include <stddef.h>
#include "common/tool.h"

/* The places tried, in this order (docs/MESH.md, "Material textures"); DIR
 * is the mesh file's folder as the loader forms it (bg_mesh_material: made
 * absolute with the current directory), BASE the written path's last
 * component:
 *   1. the path as written: an absolute path as it is, a relative one
 *      against DIR with backslashes as '/' (what bg_mesh_material holds);
 *      skipped for a Windows drive path (C:\...), which names no file here;
 *   2. DIR/BASE;  3. DIR/textures/BASE;  4. DIR/tex/BASE.
 * The fallbacks 2-4 never leave DIR (a BASE of "." or ".." is not tried).
 * A place counts when it is a regular file. */
#define MESH_TEXTURE_PLACES 4

/* UDIM tile sets (the Mari convention, docs/MESH.md "UDIM tiles"): a name
 * with this token stands for one file per tile, the token replaced by the
 * four-digit tile number 1001 + u_tile + 10 * v_tile. */
#define MESH_UDIM_TOKEN "<UDIM>"
/* `pattern` with every MESH_UDIM_TOKEN replaced by `udim` (four digits),
 * malloc'd; NULL when out of memory. */
char *mesh_udim_path(const char *pattern, int udim);

/* The label of material `index` ('name') of `mesh_path` in messages:
 * "material N 'NAME' of MESH", N as in the file's (assimp's) material order,
 * from 0. Returns buf. */
const char *mesh_texture_origin(char *buf, size_t len, const char *mesh_path, size_t index,
                                const char *name);

/* The file of the `kind` texture ("diffuse", "height", "normal") that
 * material `index` ('name') of `mesh_path` names as `path` (a
 * bg_mesh_material path). Returns the first place above that exists,
 * malloc'd (the path itself when it exists, so reports stay as they were),
 * or NULL with *e set: BG_ERR_FORMAT naming the material, the path as
 * written and every place tried, or BG_ERR_OUT_OF_MEMORY. */
char *mesh_texture_find(const char *mesh_path, size_t index, const char *name, const char *kind,
                        const char *path, bgt_err *e);

#endif
