// SPDX-License-Identifier: MIT
// Mesh loading of the tools over assimp 5 (include/bumpgrad/mesh.h).
// Every extern "C" entry point catches: a C++ exception crossing into the C
// command line would be undefined behaviour, and assimp allocates freely.
#include "bumpgrad/mesh.h"
#include "io_util.h"

#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cerrno>
#include <cmath>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <algorithm>
#include <array>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include <csignal>

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

namespace {


// Case-insensitive test of the file name's extension, which is how assimp
// itself picks an importer first.
bool has_extension(const char *path, const char *ext)
{
    const char *dot = std::strrchr(path, '.');
    const char *slash = std::strrchr(path, '/');
    if (!dot || (slash && dot < slash))
        return false;
    ++dot;
    for (; *dot && *ext; ++dot, ++ext) {
        char a = *dot, b = *ext;
        if (a >= 'A' && a <= 'Z')
            a = static_cast<char>(a - 'A' + 'a');
        if (a != b)
            return false;
    }
    return *dot == 0 && *ext == 0;
}

// A mesh of the scene with the accumulated transform of the node that uses
// it, the node (null for a mesh no node refers to) and the visit of the node
// (one per path from the root: the instances of one visit form one part).
struct instance {
    const aiMesh *mesh;
    aiMatrix4x4 transform;
    bool identity;
    const aiNode *node;
    size_t visit;
};

void collect(const aiScene *scene, const aiNode *node, const aiMatrix4x4 &parent,
             std::vector<instance> &out, int depth, size_t &visits)
{
    // A malformed file can make a node its own descendant (glTF RecursiveNodes);
    // real scene graphs are nowhere near this deep.
    if (!node || depth > 256)
        return;
    aiMatrix4x4 m = parent * node->mTransformation;
    const size_t visit = visits++;
    for (unsigned i = 0; i < node->mNumMeshes; ++i) {
        unsigned k = node->mMeshes[i];
        if (k < scene->mNumMeshes && scene->mMeshes[k])
            out.push_back({scene->mMeshes[k], m, m.IsIdentity(), node, visit});
    }
    for (unsigned i = 0; i < node->mNumChildren; ++i)
        collect(scene, node->mChildren[i], m, out, depth + 1, visits);
}

// v / |v|; v unchanged when its length is 0 or not finite (a degenerate or
// NaN normal keeps what the file holds, for the caller's sentinel rule).
aiVector3D unit_if_finite(aiVector3D v)
{
    const float len = v.Length();
    if (len > 0.0f && std::isfinite(len))
        v /= len;
    return v;
}

// One vertex's vector into the mesh's SoA arrays.
void store(float *x, float *y, float *z, size_t k, const aiVector3D &v)
{
    x[k] = v.x;
    y[k] = v.y;
    z[k] = v.z;
}

// The per-vertex arrays of a mesh, in the order the import child sends them:
// positions, normals, UVs, tangents (absent ones are NULL).
std::array<float **, 12> vertex_arrays(bg_mesh &m)
{
    return {&m.px, &m.py, &m.pz, &m.nx, &m.ny, &m.nz, &m.u, &m.v, &m.tx, &m.ty, &m.tz, &m.tw};
}

template <typename T> T *alloc_array(size_t n)
{
    // calloc checks n * size for overflow itself.
    return static_cast<T *>(std::calloc(n ? n : 1, sizeof(T)));
}

// A malloc'ed copy of s[0, n), NUL-terminated (free() in bg_mesh_free).
char *dup_string(const char *s, size_t n)
{
    char *d = static_cast<char *>(std::malloc(n + 1));
    if (d) {
        std::memcpy(d, s, n);
        d[n] = 0;
    }
    return d;
}

// s cut to at most BG_MESH_MAX_STRING bytes, at a UTF-8 character boundary.
std::string capped_name(const char *s)
{
    std::string n(s ? s : "");
    if (n.size() > BG_MESH_MAX_STRING) {
        size_t k = BG_MESH_MAX_STRING;
        while (k > 0 && (static_cast<unsigned char>(n[k]) & 0xC0) == 0x80)
            --k;
        n.resize(k);
    }
    return n;
}

// The name of the meshes m[0, n) of one node: their common name; names
// "X-0", "X-1", ... (assimp's glTF importer names the primitives of mesh X
// so) give X; else the first name.
std::string meshes_name(const std::vector<std::string> &m)
{
    if (m.empty())
        return std::string();
    if (std::all_of(m.begin(), m.end(), [&](const std::string &x) { return x == m[0]; }))
        return m[0];
    const size_t dash = m[0].rfind('-');
    if (dash == std::string::npos)
        return m[0];
    const std::string stem = m[0].substr(0, dash + 1); // "X-"
    const bool split = std::all_of(m.begin(), m.end(), [&](const std::string &x) {
        return x.size() > stem.size() && x.compare(0, stem.size(), stem) == 0 &&
               x.find_first_not_of("0123456789", stem.size()) == std::string::npos;
    });
    return split ? m[0].substr(0, dash) : m[0];
}

// The parts of the flattened mesh (bg_mesh_part): consecutive instances of
// one node visit, those without triangles left out; none over the cap.
bg_status make_parts(const std::vector<instance> &inst, bg_mesh &m)
{
    struct pending {
        size_t first, count, visit;
        const aiNode *node;
        std::vector<std::string> meshes;
    };
    std::vector<pending> parts;
    size_t t = 0;
    for (const instance &in : inst) {
        size_t nt = 0;
        for (unsigned f = 0; f < in.mesh->mNumFaces; ++f)
            nt += in.mesh->mFaces[f].mNumIndices == 3;
        if (nt == 0)
            continue;
        if (parts.empty() || parts.back().visit != in.visit)
            parts.push_back({t, 0, in.visit, in.node, {}});
        parts.back().count += nt;
        parts.back().meshes.push_back(in.mesh->mName.C_Str());
        t += nt;
    }
    if (parts.size() > BG_MESH_MAX_PARTS)
        return BG_OK;
    m.parts = alloc_array<bg_mesh_part>(parts.size());
    if (!m.parts)
        return BG_ERR_OUT_OF_MEMORY;
    m.part_count = parts.size();
    for (size_t k = 0; k < parts.size(); ++k) {
        bg_mesh_part &p = m.parts[k];
        p.first_triangle = parts[k].first;
        p.triangle_count = parts[k].count;
        const std::string name = capped_name(parts[k].node ? parts[k].node->mName.C_Str() : "");
        const std::string mesh = capped_name(meshes_name(parts[k].meshes).c_str());
        if (!(p.name = dup_string(name.data(), name.size())) ||
            !(p.mesh_name = dup_string(mesh.data(), mesh.size())))
            return BG_ERR_OUT_OF_MEMORY;
    }
    return BG_OK;
}

// The four strings of a material, in the order the import child sends them.
std::array<char **, 4> material_strings(bg_mesh_material &mm)
{
    return {&mm.name, &mm.diffuse, &mm.height, &mm.normal};
}

// The folder of the mesh file with a trailing '/', absolute (the current
// directory prefixed to a relative path), "" when neither is known.
std::string mesh_folder(const char *path)
{
    std::string dir(path);
    size_t slash = dir.rfind('/');
    dir = slash == std::string::npos ? std::string() : dir.substr(0, slash + 1);
    if (path[0] != '/') {
        char cwd[4096];
        if (getcwd(cwd, sizeof cwd))
            dir = std::string(cwd) + "/" + dir;
    }
    return dir;
}

// The first texture of `type` of material `mat` as a path resolved against
// `dir` (backslashes as '/', so spider.mtl's "map_Kd .\wal67ar_small.jpg"
// works, and a leading "./" dropped), "" for none; an embedded texture ("*N",
// or a name the scene's embedded textures hold) is skipped and counted.
std::string texture_path(const aiScene *scene, const aiMaterial *mat, aiTextureType type,
                         const std::string &dir, size_t &embedded)
{
    aiString tp;
    if (mat->GetTextureCount(type) == 0 || mat->GetTexture(type, 0, &tp) != AI_SUCCESS ||
        tp.length == 0)
        return std::string();
    std::string t(tp.C_Str());
    if (t[0] == '*' || scene->GetEmbeddedTexture(tp.C_Str())) {
        ++embedded;
        return std::string();
    }
    std::replace(t.begin(), t.end(), '\\', '/');
    if (t.compare(0, 2, "./") == 0)
        t.erase(0, 2);
    return t[0] == '/' ? t : dir + t;
}

// The scene's materials into m.materials (see bg_mesh_material).
bg_status read_materials(const aiScene *scene, const char *path, bg_mesh &m, char *err,
                         size_t errlen)
{
    if (scene->mNumMaterials == 0 || !scene->mMaterials)
        return BG_OK;
    if (scene->mNumMaterials > BG_MESH_MAX_MATERIALS) {
        bg_io_set_error(err, errlen, "'%s': %u materials, more than the %d this tool keeps", path,
                        scene->mNumMaterials, BG_MESH_MAX_MATERIALS);
        return BG_ERR_FORMAT;
    }
    const std::string dir = mesh_folder(path);
    m.materials = alloc_array<bg_mesh_material>(scene->mNumMaterials);
    if (!m.materials)
        return BG_ERR_OUT_OF_MEMORY;
    m.material_count = scene->mNumMaterials;
    for (unsigned k = 0; k < scene->mNumMaterials; ++k) {
        const aiMaterial *mat = scene->mMaterials[k];
        bg_mesh_material &mm = m.materials[k];
        std::string s[4];
        if (mat) {
            s[0] = mat->GetName().C_Str();
            s[1] = texture_path(scene, mat, aiTextureType_DIFFUSE, dir, m.embedded_textures);
            s[2] = texture_path(scene, mat, aiTextureType_HEIGHT, dir, m.embedded_textures);
            if (s[2].empty())
                s[2] = texture_path(scene, mat, aiTextureType_DISPLACEMENT, dir,
                                    m.embedded_textures);
            s[3] = texture_path(scene, mat, aiTextureType_NORMALS, dir, m.embedded_textures);
            aiColor4D c;
            if (aiGetMaterialColor(mat, AI_MATKEY_BASE_COLOR, &c) == AI_SUCCESS ||
                aiGetMaterialColor(mat, AI_MATKEY_COLOR_DIFFUSE, &c) == AI_SUCCESS) {
                const float v[4] = {c.r, c.g, c.b, c.a};
                mm.has_base_color = std::isfinite(v[0]) && std::isfinite(v[1]) &&
                                    std::isfinite(v[2]) && std::isfinite(v[3]);
                if (mm.has_base_color)
                    std::memcpy(mm.base_color, v, sizeof v);
            }
        }
        const auto dst = material_strings(mm);
        for (int i = 0; i < 4; ++i) {
            if (i > 0 && s[i].empty())
                continue;
            if (s[i].size() > BG_MESH_MAX_STRING) {
                bg_io_set_error(err, errlen,
                                "'%s': material %u names a texture or name of %zu bytes, more "
                                "than %d",
                                path, k, s[i].size(), BG_MESH_MAX_STRING);
                return BG_ERR_FORMAT;
            }
            if (!(*dst[i] = dup_string(s[i].data(), s[i].size())))
                return BG_ERR_OUT_OF_MEMORY;
        }
    }
    return BG_OK;
}

bg_status precheck(const char *path, char *err, size_t errlen)
{
    // Tell "missing / unreadable" (I/O) from "not a mesh" (format) before
    // assimp, which reports both as a failed import.
    off_t size = 0;
    bg_status st = bg_io_check_readable(path, "mesh file", err, errlen, &size);
    if (st != BG_OK)
        return st;
    if (size == 0) {
        bg_io_set_error(err, errlen, "'%s': empty file, no mesh in it", path);
        return BG_ERR_FORMAT;
    }
    return BG_OK;
}

// Every face of every mesh has indices within its mesh's vertices: checked
// before post-processing, since Debian's assimp is built with its internal
// asserts on, and a truncated PLY yields empty faces that pass its validation
// but abort() the process inside the triangulation step.
static bg_status check_faces(const aiScene *scene, const char *path, char *err, size_t errlen)
{
    for (unsigned k = 0; k < scene->mNumMeshes; ++k) {
        const aiMesh *am = scene->mMeshes[k];
        if (!am)
            continue;
        for (unsigned f = 0; f < am->mNumFaces; ++f) {
            const aiFace &face = am->mFaces[f];
            bool bad = face.mNumIndices == 0 || !face.mIndices;
            for (unsigned c = 0; !bad && c < face.mNumIndices; ++c)
                bad = face.mIndices[c] >= am->mNumVertices;
            if (bad) {
                bg_io_set_error(err, errlen,
                          "'%s': malformed mesh (face %u of mesh %u has %u vertex indices, "
                          "or one beyond its %u vertices; truncated file?)",
                          path, f, k, face.mNumIndices, am->mNumVertices);
                return BG_ERR_FORMAT;
            }
        }
    }
    return BG_OK;
}

// assimp's JoinIdenticalVertices takes a NaN position as equal to finite
// ones near it (a triangle (nan,0,0), (1,0,0), (0,1,0) came out as one
// vertex), so valid vertices would vanish. With any NaN/Inf position the
// vertices stay as imported; the bad ones get the sentinel normal later.
static bool any_nonfinite_position(const aiScene *scene)
{
    for (unsigned k = 0; k < scene->mNumMeshes; ++k) {
        const aiMesh *am = scene->mMeshes[k];
        for (unsigned v = 0; am && am->mVertices && v < am->mNumVertices; ++v) {
            const aiVector3D &p = am->mVertices[v];
            if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
                return true;
        }
    }
    return false;
}

// Import and validate, check the faces ourselves (check_faces), and only then
// post-process with pp. Null on failure, with the message in err.
static const aiScene *read_scene(Assimp::Importer &importer, const char *path, unsigned pp,
                                 char *err, size_t errlen)
{
    const aiScene *scene = importer.ReadFile(path, aiProcess_ValidateDataStructure);
    if (!scene) {
        const char *why = importer.GetErrorString();
        bg_io_set_error(err, errlen, "'%s': not a readable mesh (%s)", path,
                  why && *why ? why : "unknown format");
        return nullptr;
    }
    if (check_faces(scene, path, err, errlen) != BG_OK)
        return nullptr;
    if ((pp & aiProcess_JoinIdenticalVertices) && any_nonfinite_position(scene))
        pp &= ~static_cast<unsigned>(aiProcess_JoinIdenticalVertices);
    scene = importer.ApplyPostProcessing(pp);
    if (!scene) {
        const char *why = importer.GetErrorString();
        bg_io_set_error(err, errlen, "'%s': not a usable mesh (%s)", path,
                  why && *why ? why : "post-processing failed");
        return nullptr;
    }
    if ((scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) || scene->mNumMeshes == 0) {
        bg_io_set_error(err, errlen, "'%s': the file holds no mesh", path);
        return nullptr;
    }
    return scene;
}

// The sizes of the flattened mesh and the attributes every instance has.
struct mesh_shape {
    size_t nv = 0, nt = 0, dropped = 0;
    bool normals = true, uvs = true, tangents = true;
};

static mesh_shape shape_of(const std::vector<instance> &inst, bool drop_normals)
{
    mesh_shape s;
    s.normals = !drop_normals;
    for (const instance &in : inst) {
        const aiMesh *m = in.mesh;
        s.nv += m->mNumVertices;
        for (unsigned f = 0; f < m->mNumFaces; ++f) {
            if (m->mFaces[f].mNumIndices == 3)
                ++s.nt;
            else
                ++s.dropped;
        }
        s.normals = s.normals && m->HasNormals();
        s.uvs = s.uvs && m->HasTextureCoords(0);
        s.tangents = s.tangents && m->HasTangentsAndBitangents();
    }
    s.tangents = s.tangents && s.normals && s.uvs;
    return s;
}

// The arrays of a mesh of shape s (materials only when the scene has several).
static bool alloc_mesh(const mesh_shape &s, size_t instances, bool materials, bg_mesh &m)
{
    const size_t nv = s.nv, nt = s.nt;
    m.vertex_count = nv;
    m.triangle_count = nt;
    m.mesh_count = instances;
    m.dropped_primitives = s.dropped;
    m.px = alloc_array<float>(nv);
    m.py = alloc_array<float>(nv);
    m.pz = alloc_array<float>(nv);
    bool ok = m.px && m.py && m.pz;
    if (s.normals) {
        m.nx = alloc_array<float>(nv);
        m.ny = alloc_array<float>(nv);
        m.nz = alloc_array<float>(nv);
        ok = ok && m.nx && m.ny && m.nz;
    }
    if (s.uvs) {
        m.u = alloc_array<float>(nv);
        m.v = alloc_array<float>(nv);
        ok = ok && m.u && m.v;
    }
    if (s.tangents) {
        m.tx = alloc_array<float>(nv);
        m.ty = alloc_array<float>(nv);
        m.tz = alloc_array<float>(nv);
        m.tw = alloc_array<float>(nv);
        ok = ok && m.tx && m.ty && m.tz && m.tw;
    }
    m.indices = alloc_array<uint32_t>(nt * 3 >= nt ? nt * 3 : SIZE_MAX);
    ok = ok && m.indices;
    if (materials) {
        m.material = alloc_array<uint32_t>(nt);
        ok = ok && m.material;
    }
    return ok;
}

// One instance's vertices at `base`. Normals go through the inverse
// transpose; a tangent is a surface direction: it goes through the transform
// itself, as the bitangent does, and the sign is the handedness of (n, t, b)
// after the transform (assimp's glTF importer stores b = w cross(n, t)).
// Returns whether the transform mirrors (negative determinant), which
// reverses the winding.
static bool copy_vertices(const instance &in, const mesh_shape &s, bg_mesh &m, size_t base)
{
    const aiMesh *am = in.mesh;
    aiMatrix3x3 linear(in.transform);
    aiMatrix3x3 normal_matrix = linear;
    bool flip = false;
    if (!in.identity) {
        float det = linear.Determinant();
        flip = det < 0.0f;
        if (det != 0.0f)
            normal_matrix.Inverse().Transpose();
    }
    for (unsigned i = 0; i < am->mNumVertices; ++i) {
        aiVector3D p = am->mVertices[i];
        if (!in.identity)
            p = in.transform * p;
        store(m.px, m.py, m.pz, base + i, p);
        if (s.normals) {
            aiVector3D n = am->mNormals[i];
            if (!in.identity)
                n = unit_if_finite(normal_matrix * n);
            store(m.nx, m.ny, m.nz, base + i, n);
        }
        if (s.uvs) {
            m.u[base + i] = am->mTextureCoords[0][i].x;
            m.v[base + i] = am->mTextureCoords[0][i].y;
        }
        if (s.tangents) {
            aiVector3D n = am->mNormals[i], tg = am->mTangents[i], b = am->mBitangents[i];
            if (!in.identity) {
                n = normal_matrix * n;
                tg = linear * tg;
                b = linear * b;
            }
            tg = unit_if_finite(tg);
            store(m.tx, m.ty, m.tz, base + i, tg);
            m.tw[base + i] = ((n ^ tg) * b) < 0.0f ? -1.0f : 1.0f;
        }
    }
    return flip;
}

// One mesh's triangles from triangle *t on, indices offset by base, in the
// other winding when flip. The index and material checks repeat what
// ValidateDataStructure rejects already, so that no caller can ever index out
// of the arrays.
static bg_status copy_faces(const aiScene *scene, const aiMesh *am, bool flip, size_t base,
                            bg_mesh &m, size_t *t, const char *path, char *err, size_t errlen)
{
    if (m.material && am->mMaterialIndex >= scene->mNumMaterials) {
        bg_io_set_error(err, errlen, "'%s': mesh '%s' uses material %u of %u", path,
                        am->mName.C_Str(), am->mMaterialIndex, scene->mNumMaterials);
        return BG_ERR_FORMAT;
    }
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
        const aiFace &face = am->mFaces[f];
        if (face.mNumIndices != 3)
            continue;
        if (m.material)
            m.material[*t] = am->mMaterialIndex;
        for (unsigned c = 0; c < 3; ++c) {
            unsigned idx = face.mIndices[flip ? 2 - c : c];
            if (idx >= am->mNumVertices) {
                bg_io_set_error(err, errlen, "'%s': face %u of mesh '%s' refers to vertex %u of %u",
                          path, f, am->mName.C_Str(), idx, am->mNumVertices);
                return BG_ERR_FORMAT;
            }
            m.indices[3 * *t + c] = static_cast<uint32_t>(base + idx);
        }
        ++*t;
    }
    return BG_OK;
}

bg_status import_scene(const char *path, unsigned flags, bg_mesh *out, char *err, size_t errlen)
{
    const bool is_ply = has_extension(path, "ply");
    const bool is_stl = has_extension(path, "stl");
    unsigned join = flags & 3u;
    bool do_join = join == BG_MESH_JOIN_ALWAYS || (join == BG_MESH_JOIN_AUTO && !is_ply);
    bool drop_normals = (flags & BG_MESH_DROP_NORMALS) || is_stl;

    Assimp::Importer importer;
    unsigned pp = aiProcess_Triangulate;
    if (do_join)
        pp |= aiProcess_JoinIdenticalVertices;
    if (drop_normals) {
        // Removed before joining, so vertices that differ only by a facet
        // normal merge and smooth normals can be formed over them.
        importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS, aiComponent_NORMALS);
        pp |= aiProcess_RemoveComponent;
    }
    const aiScene *scene = read_scene(importer, path, pp, err, errlen);
    if (!scene)
        return BG_ERR_FORMAT;

    std::vector<instance> inst;
    aiMatrix4x4 identity;
    size_t visits = 0;
    collect(scene, scene->mRootNode, identity, inst, 0, visits);
    if (inst.empty()) {
        // Meshes no node refers to: take them as they are rather than lose them.
        for (unsigned k = 0; k < scene->mNumMeshes; ++k)
            if (scene->mMeshes[k])
                inst.push_back({scene->mMeshes[k], identity, true, nullptr, visits++});
    }
    const mesh_shape s = shape_of(inst, drop_normals);
    if (s.nt == 0) {
        bg_io_set_error(err, errlen, "'%s': no triangles in the mesh (%zu vertices, %zu points/lines)",
                  path, s.nv, s.dropped);
        return BG_ERR_FORMAT;
    }
    if (s.nv > UINT32_MAX) {
        bg_io_set_error(err, errlen, "'%s': %zu vertices, more than the 2^32-1 this tool indexes", path,
                  s.nv);
        return BG_ERR_FORMAT;
    }

    bg_mesh m{};
    if (!alloc_mesh(s, inst.size(), scene->mNumMaterials > 1, m)) {
        bg_mesh_free(&m);
        bg_io_set_error(err, errlen, "'%s': out of memory for %zu vertices, %zu triangles", path,
                        s.nv, s.nt);
        return BG_ERR_OUT_OF_MEMORY;
    }
    size_t base = 0, t = 0;
    for (const instance &in : inst) {
        const bool flip = copy_vertices(in, s, m, base);
        bg_status st = copy_faces(scene, in.mesh, flip, base, m, &t, path, err, errlen);
        if (st != BG_OK) {
            bg_mesh_free(&m);
            return st;
        }
        base += in.mesh->mNumVertices;
    }
    bg_status st = read_materials(scene, path, m, err, errlen);
    if (st == BG_OK && make_parts(inst, m) != BG_OK)
        st = BG_ERR_OUT_OF_MEMORY;
    if (st != BG_OK) {
        bg_mesh_free(&m);
        if (st == BG_ERR_OUT_OF_MEMORY)
            bg_io_set_error(err, errlen, "'%s': out of memory for its materials and parts", path);
        return st;
    }
    *out = m;
    return BG_OK;
}

bg_status import_guarded(const char *path, unsigned flags, bg_mesh *out, char *err,
                         size_t errlen)
{
    return bg_io_guard("'" + std::string(path) + "'", "out of memory while loading",
                       "not a readable mesh", BG_ERR_FORMAT, err, errlen,
                       [&] { return import_scene(path, flags, out, err, errlen); },
                       [&] { bg_mesh_free(out); });
}

// ---- the import in a child process ----
// Debian's assimp is built with its internal asserts on (they call abort()),
// and malformed files have crashed its importers before; neither can be caught
// in-process. So the import runs in a forked child that sends the flattened
// mesh back through a pipe: a crash becomes an error message naming the file,
// and the parent never holds assimp's scene, which also lowers its peak memory.

struct wire_header {
    int32_t status;
    int32_t has_normals, has_uvs, has_tangents, has_material_ids;
    uint64_t vertex_count, triangle_count, mesh_count, dropped, material_count, embedded;
    uint64_t part_count;
    char err[512];
};

bool write_all(int fd, const void *p, size_t n) { return bg_io_write_all(fd, p, n) == n; }

bool read_all(int fd, void *p, size_t n) { return bg_io_read_all(fd, p, n) == n; }

// Cap the child's address space. A corrupt count in a header (assimp's own
// test file invalid/OutOfMemory.off claims 3.5e9 vertices) otherwise makes the
// importer reserve tens of GB, which overcommit grants, and then fill it, so
// the machine swaps instead of the load failing. Real imports need a small
// multiple of the file size (measured: ~7x for a binary PLY, docs/MESH.md).
// BUMPGRAD_MESH_MAX_MB overrides the extra allowance; 0 disables the cap.
size_t child_memory_cap(const char *path)
{
    return bg_io_child_memory_cap(path, "BUMPGRAD_MESH_MAX_MB");
}

[[noreturn]] void child_main(int fd, const char *path, unsigned flags, pid_t parent_pid)
{
    bg_mesh m{};
    wire_header h{};
    size_t cap = child_memory_cap(path);
    bg_io_child_limits(parent_pid, cap, bg_io_child_timeout());
    h.status = import_guarded(path, flags, &m, h.err, sizeof h.err);
    // assimp catches its own std::bad_alloc and reports it as an import
    // error: under a cap, that is the cap speaking, not the file.
    const bool oom = h.status == BG_ERR_OUT_OF_MEMORY ||
                     (h.status != BG_OK && (std::strstr(h.err, "bad_alloc") ||
                                            std::strstr(h.err, "out of memory")));
    const char *env = std::getenv("BUMPGRAD_MESH_MAX_MB");
    if (oom && cap && env && *env) {
        bg_io_set_error(h.err, sizeof h.err,
                  "'%s': the import ran out of memory under BUMPGRAD_MESH_MAX_MB=%s (%zu MiB "
                  "in all for the import process); raise it, or unset it for the default",
                  path, env, cap >> 20);
        h.status = BG_ERR_INVALID_ARGUMENT;
    } else if (oom && cap) {
        bg_io_set_error(h.err, sizeof h.err,
                  "'%s': the import needs more than %zu MiB, far more than a file of this "
                  "size should (corrupt counts in the file?); set BUMPGRAD_MESH_MAX_MB to "
                  "allow more",
                  path, cap >> 20);
        h.status = BG_ERR_FORMAT;
    }
    h.has_normals = m.nx != nullptr;
    h.has_uvs = m.u != nullptr;
    h.has_tangents = m.tx != nullptr;
    h.vertex_count = m.vertex_count;
    h.triangle_count = m.triangle_count;
    h.mesh_count = m.mesh_count;
    h.dropped = m.dropped_primitives;
    h.has_material_ids = m.material != nullptr;
    h.material_count = m.material_count;
    h.embedded = m.embedded_textures;
    h.part_count = m.part_count;
    bool ok = write_all(fd, &h, sizeof h);
    size_t nv = m.vertex_count * sizeof(float);
    for (float **a : vertex_arrays(m))
        if (ok && *a)
            ok = write_all(fd, *a, nv);
    if (ok && h.status == BG_OK)
        ok = write_all(fd, m.indices, m.triangle_count * 3 * sizeof(uint32_t));
    if (ok && m.material)
        ok = write_all(fd, m.material, m.triangle_count * sizeof(uint32_t));
    // Each material's strings: a uint32 length (UINT32_MAX for NULL), then its bytes.
    for (size_t k = 0; ok && k < m.material_count; ++k)
        for (char **str : material_strings(m.materials[k])) {
            const uint32_t len = *str ? static_cast<uint32_t>(std::strlen(*str)) : UINT32_MAX;
            ok = write_all(fd, &len, sizeof len) && (!*str || write_all(fd, *str, len));
        }
    // Then each material's base colour: the flag (int32) and 4 floats.
    for (size_t k = 0; ok && k < m.material_count; ++k) {
        const int32_t has = m.materials[k].has_base_color;
        ok = write_all(fd, &has, sizeof has) &&
             write_all(fd, m.materials[k].base_color, sizeof m.materials[k].base_color);
    }
    // Then each part: its first triangle and count (uint64), its two strings.
    for (size_t k = 0; ok && k < m.part_count; ++k) {
        const bg_mesh_part &p = m.parts[k];
        const uint64_t range[2] = {p.first_triangle, p.triangle_count};
        ok = write_all(fd, range, sizeof range);
        for (const char *str : {p.name, p.mesh_name}) {
            const uint32_t len = static_cast<uint32_t>(std::strlen(str));
            ok = ok && write_all(fd, &len, sizeof len) && write_all(fd, str, len);
        }
    }
    // _exit: no atexit handlers or stdio flushes of the parent's state.
    _exit(ok ? 0 : 1);
}

// The material ids and materials after the indices (child_main), checked
// against the caps: at most BG_MESH_MAX_MATERIALS, strings of at most
// BG_MESH_MAX_STRING bytes, every id below the count. A violation clears
// `got` (a malformed stream: the caller reports "stopped without a result").
int read_wire_materials(int fd, const wire_header &h, bg_mesh &m, bool &got)
{
    if (h.material_count > BG_MESH_MAX_MATERIALS || (h.has_material_ids && h.material_count == 0)) {
        got = false;
        return BG_OK;
    }
    m.embedded_textures = h.embedded;
    if (h.has_material_ids) {
        if (!(m.material = alloc_array<uint32_t>(m.triangle_count)))
            return BG_ERR_OUT_OF_MEMORY;
        got = read_all(fd, m.material, m.triangle_count * sizeof(uint32_t));
        for (size_t t = 0; got && t < m.triangle_count; ++t)
            got = m.material[t] < h.material_count;
    }
    if (!got || h.material_count == 0)
        return BG_OK;
    if (!(m.materials = alloc_array<bg_mesh_material>(h.material_count)))
        return BG_ERR_OUT_OF_MEMORY;
    m.material_count = h.material_count;
    for (size_t k = 0; got && k < m.material_count; ++k)
        for (char **str : material_strings(m.materials[k])) {
            uint32_t len = 0;
            got = read_all(fd, &len, sizeof len) &&
                  (len <= BG_MESH_MAX_STRING || (len == UINT32_MAX && str != &m.materials[k].name));
            if (!got)
                break;
            if (len == UINT32_MAX)
                continue;
            if (!(*str = alloc_array<char>(static_cast<size_t>(len) + 1)))
                return BG_ERR_OUT_OF_MEMORY;
            got = read_all(fd, *str, len);
            // a NUL inside would cut the string short silently: refuse the stream
            got = got && std::memchr(*str, 0, len) == nullptr;
        }
    for (size_t k = 0; got && k < m.material_count; ++k) {
        bg_mesh_material &mm = m.materials[k];
        int32_t has = 0;
        got = read_all(fd, &has, sizeof has) && read_all(fd, mm.base_color, sizeof mm.base_color);
        got = got && (has == 0 || has == 1);
        for (int i = 0; got && i < 4; ++i)
            got = !has || std::isfinite(mm.base_color[i]);
        mm.has_base_color = got && has;
    }
    return BG_OK;
}

// The parts after the materials (child_main), checked against the caps: at
// most BG_MESH_MAX_PARTS, strings of at most BG_MESH_MAX_STRING bytes
// without a NUL, non-empty ranges that follow each other and cover every
// triangle. A violation clears `got`.
int read_wire_parts(int fd, const wire_header &h, bg_mesh &m, bool &got)
{
    if (!got || h.part_count == 0)
        return BG_OK;
    if (h.part_count > BG_MESH_MAX_PARTS || h.part_count > m.triangle_count) {
        got = false;
        return BG_OK;
    }
    if (!(m.parts = alloc_array<bg_mesh_part>(h.part_count)))
        return BG_ERR_OUT_OF_MEMORY;
    m.part_count = h.part_count;
    size_t end = 0;
    for (size_t k = 0; got && k < m.part_count; ++k) {
        bg_mesh_part &p = m.parts[k];
        uint64_t range[2] = {0, 0};
        got = read_all(fd, range, sizeof range) && range[0] == end && range[1] > 0 &&
              range[1] <= m.triangle_count - end;
        if (!got)
            break;
        p.first_triangle = end;
        p.triangle_count = range[1];
        end += range[1];
        for (char **str : {&p.name, &p.mesh_name}) {
            uint32_t len = 0;
            got = got && read_all(fd, &len, sizeof len) && len <= BG_MESH_MAX_STRING;
            if (!got)
                break;
            if (!(*str = alloc_array<char>(static_cast<size_t>(len) + 1)))
                return BG_ERR_OUT_OF_MEMORY;
            got = read_all(fd, *str, len) && std::memchr(*str, 0, len) == nullptr;
        }
    }
    got = got && end == m.triangle_count;
    return BG_OK;
}

// BG_OK/BG_ERR_*: the load's result; -1: could not start a child (the caller
// then loads in-process).
int load_isolated(const char *path, unsigned flags, bg_mesh *out, char *err, size_t errlen)
{
    int fds[2];
    // O_CLOEXEC: a program the child starts (ASan's symbolizer, on a report)
    // must not hold the write end open, or the parent would wait for ever.
    if (pipe2(fds, O_CLOEXEC) != 0)
        return -1;
    pid_t parent = getpid();
    pid_t pid = fork();
    if (pid < 0) {
        close(fds[0]);
        close(fds[1]);
        return -1;
    }
    if (pid == 0) {
        close(fds[0]);
        // A parent that stops reading (out of memory) must end the child, not
        // leave it blocked: the default SIGPIPE action does that.
        signal(SIGPIPE, SIG_DFL);
        child_main(fds[1], path, flags, parent);
    }
    close(fds[1]);
    wire_header h{};
    bg_mesh m{};
    int rc = BG_OK;
    bool got = read_all(fds[0], &h, sizeof h);
    if (got && h.status == BG_OK) {
        if (h.vertex_count > UINT32_MAX || h.triangle_count > SIZE_MAX / 12) {
            got = false;
        } else {
            m.vertex_count = h.vertex_count;
            m.triangle_count = h.triangle_count;
            m.mesh_count = h.mesh_count;
            m.dropped_primitives = h.dropped;
            size_t nv = m.vertex_count;
            const auto arrays = vertex_arrays(m);
            for (int k = 0; k < 12 && got; ++k) {
                if ((k >= 3 && k < 6 && !h.has_normals) || (k >= 6 && k < 8 && !h.has_uvs) ||
                    (k >= 8 && !h.has_tangents))
                    continue;
                *arrays[k] = alloc_array<float>(nv);
                if (!*arrays[k]) {
                    rc = BG_ERR_OUT_OF_MEMORY;
                    break;
                }
                got = read_all(fds[0], *arrays[k], nv * sizeof(float));
            }
            if (got && rc == BG_OK) {
                m.indices = alloc_array<uint32_t>(m.triangle_count * 3);
                if (!m.indices)
                    rc = BG_ERR_OUT_OF_MEMORY;
                else
                    got = read_all(fds[0], m.indices, m.triangle_count * 3 * sizeof(uint32_t));
            }
            if (got && rc == BG_OK)
                rc = read_wire_materials(fds[0], h, m, got);
            if (got && rc == BG_OK)
                rc = read_wire_parts(fds[0], h, m, got);
        }
    }
    close(fds[0]);
    int wstatus = 0;
    while (waitpid(pid, &wstatus, 0) < 0 && errno == EINTR) {
    }
    if (rc == BG_ERR_OUT_OF_MEMORY) {
        bg_io_set_error(err, errlen, "'%s': out of memory for %zu vertices, %zu triangles", path,
                  m.vertex_count, m.triangle_count);
        bg_mesh_free(&m);
        return BG_ERR_OUT_OF_MEMORY;
    }
    if (!got) {
        bg_mesh_free(&m);
        if (WIFSIGNALED(wstatus) && WTERMSIG(wstatus) == SIGALRM)
            bg_io_set_error(err, errlen,
                      "'%s': the mesh importer (assimp) took more than %u s on this file and "
                      "was stopped (set BUMPGRAD_CHILD_TIMEOUT to allow more)",
                      path, bg_io_child_timeout());
        else if (WIFSIGNALED(wstatus))
            bg_io_set_error(err, errlen,
                      "'%s': the mesh importer (assimp) crashed on this file (signal %d); "
                      "it is probably corrupt",
                      path, WTERMSIG(wstatus));
        else if (WIFEXITED(wstatus) && WEXITSTATUS(wstatus) == BG_IO_CHILD_OVER_CAP)
            bg_io_set_error(err, errlen,
                      "'%s': the mesh import ran out of its memory cap (BUMPGRAD_MESH_MAX_MB "
                      "sets it)", path);
        else
            bg_io_set_error(err, errlen, "'%s': the mesh importer stopped without a result", path);
        return BG_ERR_FORMAT;
    }
    if (h.status != BG_OK) {
        h.err[sizeof h.err - 1] = 0;
        bg_io_set_error(err, errlen, "%s", h.err);
        return h.status;
    }
    *out = m;
    return BG_OK;
}

bg_status export_scene(const char *path, const char *format_id, const bg_mesh *m, char *err,
                       size_t errlen)
{
    if (m->vertex_count > UINT32_MAX || m->triangle_count > UINT32_MAX) {
        bg_io_set_error(err, errlen, "'%s': mesh too large to export", path);
        return BG_ERR_INVALID_ARGUMENT;
    }
    const unsigned nv = static_cast<unsigned>(m->vertex_count);
    const unsigned nt = static_cast<unsigned>(m->triangle_count);
    // The scene owns everything below (aiScene's destructor deletes its
    // meshes, materials and nodes, aiMesh's its arrays).
    std::unique_ptr<aiScene> scene(new aiScene());
    scene->mRootNode = new aiNode();
    scene->mRootNode->mNumMeshes = 1;
    scene->mRootNode->mMeshes = new unsigned[1]{0};
    scene->mNumMaterials = 1;
    scene->mMaterials = new aiMaterial *[1] { new aiMaterial() };
    scene->mNumMeshes = 1;
    scene->mMeshes = new aiMesh *[1] { new aiMesh() };
    aiMesh *am = scene->mMeshes[0];
    am->mMaterialIndex = 0;
    am->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
    am->mNumVertices = nv;
    am->mVertices = new aiVector3D[nv];
    if (m->nx)
        am->mNormals = new aiVector3D[nv];
    if (m->u) {
        am->mTextureCoords[0] = new aiVector3D[nv];
        am->mNumUVComponents[0] = 2;
    }
    for (unsigned i = 0; i < nv; ++i) {
        am->mVertices[i] = aiVector3D(m->px[i], m->py[i], m->pz[i]);
        if (m->nx)
            am->mNormals[i] = aiVector3D(m->nx[i], m->ny[i], m->nz[i]);
        if (m->u)
            am->mTextureCoords[0][i] = aiVector3D(m->u[i], m->v[i], 0.0f);
    }
    am->mNumFaces = nt;
    am->mFaces = new aiFace[nt];
    for (unsigned t = 0; t < nt; ++t) {
        aiFace &f = am->mFaces[t];
        f.mNumIndices = 3;
        f.mIndices = new unsigned[3];
        for (unsigned c = 0; c < 3; ++c)
            f.mIndices[c] = m->indices[3 * static_cast<size_t>(t) + c];
    }
    // assimp's exporters ignore their own write errors (a full disk gave an
    // .obj cut in the middle of a line, exit 0), so a one-file format is
    // exported to memory and written here, where every write, the fsync and
    // the close are checked. Formats that export several files (their blob
    // has a `next`) are left to assimp's own writer.
    Assimp::Exporter exporter;
    const aiExportDataBlob *blob = exporter.ExportToBlob(scene.get(), format_id);
    if (!blob) {
        const char *why = exporter.GetErrorString();
        bg_io_set_error(err, errlen, "'%s': the mesh exporter (assimp, %s) failed: %s", path, format_id,
                  why && *why ? why : "unknown error");
        return BG_ERR_IO;
    }
    if (blob->next) {
        if (exporter.Export(scene.get(), format_id, path) != AI_SUCCESS) {
            const char *why = exporter.GetErrorString();
            bg_io_set_error(err, errlen, "'%s': the mesh exporter (assimp, %s) failed: %s", path,
                            format_id, why && *why ? why : "unknown error");
            return BG_ERR_IO;
        }
        return BG_OK;
    }
    const int fd = ::open(path, O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd < 0) {
        bg_io_set_error(err, errlen, "cannot write '%s': %s", path, std::strerror(errno));
        return BG_ERR_IO;
    }
    const size_t put = bg_io_write_all(fd, blob->data, blob->size);
    int why = put == blob->size ? 0 : (errno ? errno : EIO);
    if (!why && ::fsync(fd) != 0 && errno != EINVAL && errno != EROFS)
        why = errno;
    if (::close(fd) != 0 && !why)
        why = errno;
    if (why) {
        bg_io_set_error(err, errlen, "cannot write '%s': %s", path, std::strerror(why));
        return BG_ERR_IO;
    }
    return BG_OK;
}

} // namespace

extern "C" {

bg_status bg_mesh_export(const char *path, const char *format_id, const bg_mesh *mesh, char *err,
                         size_t errlen)
{
    if (!path || !format_id || !mesh || !mesh->px || !mesh->indices) {
        bg_io_set_error(err, errlen, "bg_mesh_export: NULL argument");
        return BG_ERR_NULL_POINTER;
    }
    return bg_io_guard("'" + std::string(path) + "'", "out of memory while exporting",
                       "the mesh exporter failed", BG_ERR_IO, err, errlen,
                       [&] { return export_scene(path, format_id, mesh, err, errlen); });
}

bg_status bg_mesh_load_ex(const char *path, unsigned flags, bg_mesh *out, char *err,
                          size_t errlen)
{
    if (err && errlen)
        err[0] = 0;
    if (!out)
        return BG_ERR_NULL_POINTER;
    std::memset(out, 0, sizeof *out);
    if (!path)
        return BG_ERR_NULL_POINTER;
    if (flags & ~7u || (flags & 3u) == 3u) {
        bg_io_set_error(err, errlen, "'%s': invalid mesh loading flags %#x", path, flags);
        return BG_ERR_INVALID_ARGUMENT;
    }
    bg_status st = precheck(path, err, errlen);
    if (st != BG_OK)
        return st;
    int rc = load_isolated(path, flags, out, err, errlen);
    if (rc >= 0)
        return static_cast<bg_status>(rc);
    // No child process available (fork or pipe refused): the same import,
    // in-process, without the crash isolation.
    return import_guarded(path, flags, out, err, errlen);
}

bg_status bg_mesh_load(const char *path, bg_mesh *out, char *err, size_t errlen)
{
    return bg_mesh_load_ex(path, BG_MESH_JOIN_AUTO, out, err, errlen);
}

void bg_mesh_free(bg_mesh *mesh)
{
    if (!mesh)
        return;
    for (float **a : vertex_arrays(*mesh))
        std::free(*a);
    std::free(mesh->indices);
    std::free(mesh->material);
    for (size_t k = 0; mesh->materials && k < mesh->material_count; ++k)
        for (char **str : material_strings(mesh->materials[k]))
            std::free(*str);
    std::free(mesh->materials);
    for (size_t k = 0; mesh->parts && k < mesh->part_count; ++k) {
        std::free(mesh->parts[k].name);
        std::free(mesh->parts[k].mesh_name);
    }
    std::free(mesh->parts);
    std::memset(mesh, 0, sizeof *mesh);
}

} // extern "C"
