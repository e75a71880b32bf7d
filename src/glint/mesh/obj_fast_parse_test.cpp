// glint's OBJ parser (obj_fast_parse.h) against assimp's OBJ importer, differentially: every OBJ
// file of the repository (scenes/, the fuzz corpus), of Debian's assimp-testmodels and a set of
// generated ones (the benchmark's torus in the ways it can be written, and the subset's corners)
// is read both ways, and the meshes must be the same to the bit — positions, normals, texture
// coordinates, colours, triangle order, materials, dropped triangles — or the file must be one the
// fast path leaves to assimp. Through readMeshFile (the import child) both ways the answer, or the
// refusal's words, must be identical — unless the file has a malformed statement (obj_check.h),
// which glint refuses at its place.
#include "glint/mesh/obj_fast_parse.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <numbers>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "glint/core/file_access.h"
#include "glint/mesh/assimp_import.h"
#include "glint/mesh/mesh_file.h"
#include "glint/mesh/mesh_test_support.h"
#include "glint/mesh/obj_check.h"

namespace glint::mesh_test {
namespace {

// Bit-for-bit equality of arrays of plain values (−0 and +0 differ, and NaNs by their payload).
template <typename T>
bool sameBits(const std::vector<T>& a, const std::vector<T>& b) {
  static_assert(std::is_trivially_copyable_v<T>);
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}
template <typename T>
bool sameBits(const T& a, const T& b) {
  static_assert(std::is_trivially_copyable_v<T>);
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}

bool sameMaterial(const Material& a, const Material& b) {
  return sameBits(a.kd, b.kd) && sameBits(a.ks, b.ks) && sameBits(a.shininess, b.shininess) &&
         sameBits(a.kr, b.kr) && sameBits(a.kt, b.kt) && sameBits(a.ka, b.ka) &&
         sameBits(a.ior, b.ior) && sameBits(a.reflectionBlur, b.reflectionBlur) &&
         sameBits(a.refractionBlur, b.refractionBlur) && a.priority == b.priority &&
         a.textures == b.textures;
}

// Where two mesh files differ, or "" when they are the same to the bit.
std::string difference(const MeshFile& a, const MeshFile& b) {
  if (a.droppedTriangles != b.droppedTriangles) return "dropped triangles";
  if (a.parts.size() != b.parts.size()) return "number of parts";
  if (a.materials.size() != b.materials.size()) return "number of materials";
  if (a.embeddedImages != b.embeddedImages) return "embedded images";
  for (std::size_t i = 0; i < a.parts.size(); ++i) {
    const TriangleMesh& p = a.parts[i];
    const TriangleMesh& q = b.parts[i];
    const std::string part = "part " + std::to_string(i) + ": ";
    if (!sameBits(p.positions, q.positions)) return part + "positions";
    if (!sameBits(p.normals, q.normals)) return part + "normals";
    if (!sameBits(p.indices, q.indices)) return part + "indices";
    if (!sameBits(p.uvs, q.uvs)) return part + "uvs";
    if (!sameBits(p.colors, q.colors)) return part + "colours";
    if (!p.tangents.empty() || !q.tangents.empty()) return part + "tangents";
    if (p.materialIndex != q.materialIndex) return part + "material index";
    if (!sameBits(p.emission, q.emission)) return part + "emission";
  }
  for (std::size_t i = 0; i < a.materials.size(); ++i) {
    const MeshMaterial& m = a.materials[i];
    const MeshMaterial& n = b.materials[i];
    const std::string material = "material " + std::to_string(i) + ": ";
    if (m.name != n.name) return material + "name '" + m.name + "' / '" + n.name + "'";
    if (!sameMaterial(m.material, n.material)) return material + "coefficients";
    if (!sameBits(m.emission, n.emission) || m.fromFile != n.fromFile) return material + "emission";
    for (std::size_t k = 0; k < m.textures.size(); ++k) {
      if (m.textures[k].file != n.textures[k].file ||
          m.textures[k].embedded != n.textures[k].embedded) {
        return material + "textures";
      }
    }
  }
  return "";
}

// readMeshFile's answer (the import child, as glint reads meshes) with GLINT_OBJ_READER as given
// (nullptr: unset), or its refusal.
struct ChildAnswer {
  std::optional<MeshFile> file;
  std::string refusal;
};
ChildAnswer readInChild(const fs::path& path, const char* reader) {
  if (reader != nullptr) {
    ::setenv("GLINT_OBJ_READER", reader, 1);
  } else {
    ::unsetenv("GLINT_OBJ_READER");
  }
  ChildAnswer answer;
  try {
    answer.file = readMeshFile(path, {path.parent_path()});
  } catch (const MeshLoadError& e) {
    answer.refusal = e.what();
  }
  ::unsetenv("GLINT_OBJ_READER");
  return answer;
}

std::string readFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A fault's refusal as the reader words it (meshErrorPlace reads it back).
std::string locatedReason(const ObjFault& fault) {
  return "invalid file: line " + std::to_string(fault.line) + ", column " +
         std::to_string(fault.column) + ": " + fault.what;
}

// Whether glint's parser took `path` (in this process), after checking that it gives what
// assimp gives, in this process and through the import child. A file assimp refuses must not be
// taken.
bool readsTheSame(const fs::path& path) {
  SCOPED_TRACE(path.string());
  const ReferencedFileRule rule(path, path.parent_path());
  std::optional<MeshFile> fast;
  try {
    fast = importSimpleObj(path, rule);
  } catch (const MeshLoadError& e) {
    EXPECT_TRUE(meshErrorPlace(e.what())) << e.what();  // only a located refusal
  }
  if (fast) {
    std::optional<MeshFile> reference;
    try {
      reference = importMeshWithAssimp(path, ".obj", rule);
    } catch (const MeshLoadError& e) {
      ADD_FAILURE() << "glint's parser read a file assimp refuses: " << e.what();
    }
    if (reference) {
      EXPECT_EQ(difference(*fast, *reference), "");
    }
  }
  const ChildAnswer viaDefault = readInChild(path, nullptr);
  if (!fast) {
    if (const std::optional<ObjFault> fault = findObjFault(readFile(path))) {
      // Refused at the statement's place, whatever assimp makes of the file.
      EXPECT_EQ(viaDefault.refusal, locatedReason(*fault));
      return false;
    }
  }
  const ChildAnswer viaAssimp = readInChild(path, "assimp");
  EXPECT_EQ(viaDefault.refusal, viaAssimp.refusal);
  EXPECT_EQ(viaDefault.file.has_value(), viaAssimp.file.has_value());
  if (viaDefault.file && viaAssimp.file) {
    EXPECT_EQ(difference(*viaDefault.file, *viaAssimp.file), "");
  }
  if (fast && viaDefault.file) {
    EXPECT_EQ(difference(*fast, *viaDefault.file), "");
  }
  return fast.has_value();
}

std::vector<fs::path> objFilesUnder(const fs::path& folder) {
  std::vector<fs::path> files;
  if (!fs::is_directory(folder)) return files;
  for (const auto& entry : fs::recursive_directory_iterator(folder)) {
    if (entry.is_regular_file() && entry.path().extension() == ".obj") files.push_back(entry);
  }
  std::sort(files.begin(), files.end());
  return files;
}

TEST(ObjFastParse, RepositoryAndTestModelOBJFilesReadTheSame) {
  std::vector<fs::path> files = objFilesUnder(fs::path(GLINT_SOURCE_DIR) / "scenes");
  const std::vector<fs::path> corpus = objFilesUnder(fs::path(GLINT_SOURCE_DIR) / "fuzz/corpus");
  const std::vector<fs::path> models = objFilesUnder(kModels / "OBJ");
  ASSERT_TRUE(installed(kModels / "OBJ/box.obj"));
  files.insert(files.end(), corpus.begin(), corpus.end());
  files.insert(files.end(), models.begin(), models.end());
  ASSERT_GE(files.size(), 40u);
  std::size_t taken = 0;
  for (const fs::path& file : files) taken += readsTheSame(file) ? 1 : 0;
  // Most of them name materials (mtllib, usemtl), which the subset leaves to assimp; the plain
  // ones take the fast path (multiple_spaces.obj here and in the corpus).
  EXPECT_GE(taken, 2u) << "of " << files.size();
  EXPECT_TRUE(readsTheSame(kModels / "OBJ/multiple_spaces.obj"));
}

// The benchmark's torus (bench/bench_support.cpp, makeTorus and writeObj), written in the
// variants a generated mesh comes in.
struct TorusOptions {
  int major = 100, minor = 50;
  bool normals = true;
  bool uvs = false;
  bool quads = false;
  const char* newline = "\n";
  bool lastNewline = true;
};

std::string torusObj(const TorusOptions& o) {
  std::string text = "# generated torus\n";
  char line[160];
  const auto add = [&](const std::string& s) { text += s + o.newline; };
  constexpr double kTwoPi = 2 * std::numbers::pi;
  for (int i = 0; i < o.major; ++i) {
    const double u = kTwoPi * i / o.major;
    for (int j = 0; j < o.minor; ++j) {
      const double v = kTwoPi * j / o.minor;
      const double ring = 1.0 + 0.4 * std::cos(v);
      std::snprintf(line, sizeof line, "v %.9g %.9g %.9g", ring * std::cos(u),
                    0.5 + 0.4 * std::sin(v), ring * std::sin(u));
      add(line);
    }
  }
  if (o.normals) {
    for (int i = 0; i < o.major; ++i) {
      const double u = kTwoPi * i / o.major;
      for (int j = 0; j < o.minor; ++j) {
        const double v = kTwoPi * j / o.minor;
        std::snprintf(line, sizeof line, "vn %.9g %.9g %.9g", std::cos(v) * std::cos(u),
                      std::sin(v), std::cos(v) * std::sin(u));
        add(line);
      }
    }
  }
  if (o.uvs) {
    for (int i = 0; i < o.major; ++i) {
      for (int j = 0; j < o.minor; ++j) {
        std::snprintf(line, sizeof line, "vt %.9g %.9g", double(i) / o.major, double(j) / o.minor);
        add(line);
      }
    }
  }
  const auto corner = [&](int i, int j) {
    const int k = (i % o.major) * o.minor + (j % o.minor) + 1;
    if (o.normals && o.uvs)
      return " " + std::to_string(k) + "/" + std::to_string(k) + "/" + std::to_string(k);
    if (o.normals) return " " + std::to_string(k) + "//" + std::to_string(k);
    if (o.uvs) return " " + std::to_string(k) + "/" + std::to_string(k);
    return " " + std::to_string(k);
  };
  for (int i = 0; i < o.major; ++i) {
    for (int j = 0; j < o.minor; ++j) {
      if (o.quads) {
        add("f" + corner(i, j) + corner(i, j + 1) + corner(i + 1, j + 1) + corner(i + 1, j));
      } else {
        add("f" + corner(i, j) + corner(i, j + 1) + corner(i + 1, j + 1));
        add("f" + corner(i, j) + corner(i + 1, j + 1) + corner(i + 1, j));
      }
    }
  }
  if (!o.lastNewline) text.resize(text.size() - std::strlen(o.newline));
  return text;
}

TEST(ObjFastParse, TheBenchmarkTorusInEveryVariantReadsTheSame) {
  TempDir dir;
  struct Variant {
    const char* name;
    TorusOptions options;
  };
  const Variant variants[] = {
      {"normals", {}},
      {"no_normals", {.normals = false}},  // assimp's GenSmoothNormals on glint's scene
      {"uvs_normals", {.uvs = true}},
      {"uvs", {.normals = false, .uvs = true}},
      {"quads", {.quads = true}},  // assimp's Triangulate on glint's scene
      {"quads_uvs_no_normals", {.normals = false, .uvs = true, .quads = true}},
      {"crlf", {.newline = "\r\n"}},
      {"no_last_newline", {.lastNewline = false}},
      {"crlf_no_last_newline", {.newline = "\r\n", .lastNewline = false}},
  };
  for (const Variant& v : variants) {
    EXPECT_TRUE(readsTheSame(dir.write(std::string(v.name) + ".obj", torusObj(v.options))))
        << v.name;
  }
}

TEST(ObjFastParse, TheSubsetsCornersReadTheSame) {
  TempDir dir;
  // Each file lies in the subset: the fast path takes it, and gives what assimp gives.
  const std::pair<const char*, const char*> files[] = {
      {"spelling",
       "# numbers in every spelling the subset takes\n"
       "v +1.5e-3 -0 0.000000000000000000001234\n"
       "v 12.5 1E1 2.71828182845904523536028747135\n"
       "v -7 0.1 1e-40\n"
       "v 00012.50 3.4e+1 -0.0\n"
       "v 123456789012345678901234 1 2\n"  // past 64 bits: assimp's parse gives 0
       "f 1 2 3\nf 1 2 4\nf 2 3 4\nf 3 4 5\n"},
      {"blanks_tabs_comments",
       "\n# comment with ünïcode and \t tabs\n  \t\n"
       "o\tThe_Object  \n"
       "v\t0 0 0\t\nv  1  0  0  \nv 0 1 0\nv 0 0 1\n"
       "s 1\ns off\nsomething assimp skips as a smoothing group\n"
       "f 1 2 3   \nf\t1\t2\t4\n#end"},
      {"degenerate_and_duplicates",
       "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 0\nv 1 0 0\nv 2 0 0\nv 1e39 0 0\n"
       "vn 0 0 1\nvn 0 0 0\nvn 0 0 -0\n"
       "f 1//1 2//1 3//1\nf 4//1 5//1 3//1\nf 1//2 2//2 6//2\nf 1//3 7//3 3//3\n"
       "f 1//2 2//3 3//1\n"},
      {"uv3_and_overflowing_uv",
       "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
       "vt 0 0 0\nvt 1 0 0.5\nvt 0 1e50\nvt 0.25 0.75\n"
       "f 1/1 2/2 3/3\nf 2/4 4/1 3/2\n"},
      {"forward_references",
       "f 1//1 2//1 3//1\nf 3//1 2//1 4//1\n"
       "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0.5\nvn 0 0.6 0.8\n"},
      {"pentagon_and_concave_quad",
       "v 0 0 0\nv 2 0 0\nv 2 2 0\nv 1 0.5 0\nv 0 2 0\nv 3 1 0\nv 2.5 3 0\n"
       "f 1 2 3 4 5\nf 2 6 7 3\nf 1 2 4 3\n"},
      {"texture_and_normal_corners",
       "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 1\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\nvn 0 1 0\n"
       "f 1/1/1 2/2/1 3/3/2 4/1/2\nf 4/3/1 3/2/2 2/1/1\n"},
  };
  for (const auto& [name, text] : files) {
    EXPECT_TRUE(readsTheSame(dir.write(std::string(name) + ".obj", text))) << name;
  }
}

TEST(ObjFastParse, FilesOutsideTheSubsetAreLeftToAssimp) {
  TempDir dir;
  const std::string triangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  // assimp's own reading of each (or its refusal) is what glint gives: the fast path declines.
  const std::pair<const char*, std::string> files[] = {
      {"relative_indices", triangle + "f -3 -2 -1\n"},
      {"leading_zero_index", triangle + "f 01 2 3\n"},
      {"mixed_corner_forms", triangle + "vn 0 0 1\nf 1//1 2//1 3//1\nf 1 2 3\n"},
      {"texture_index_before_any_vt", triangle + "vn 0 0 1\nf 1/1 2/1 3/1\nvt 0 0\n"},
      {"leading_dot", "v .5 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 2 3 4\n"},
      {"four_components", "v 0 0 0 1\nv 1 0 0 1\nv 0 1 0 2\nf 1 2 3\n"},
      {"vertex_colours", "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nf 1 2 3\n"},
      {"group", triangle + "g part\nf 1 2 3\n"},
      {"usemtl", triangle + "usemtl red\nf 1 2 3\n"},
      {"mtllib", "mtllib none.mtl\n" + triangle + "f 1 2 3\n"},
      {"line", triangle + "l 1 2\nf 1 2 3\n"},
      {"point", triangle + "p 1\nf 1 2 3\n"},
      {"two_corners", triangle + "f 1 2\nf 1 2 3\n"},
      {"indented_line", triangle + " f 1 2 3\nf 1 2 3\n"},
      {"continued_line", "v 0 0 0\nv 1 0 \\\n0\nv 0 1 0\nf 1 2 3\n"},
      {"nul", std::string("v 0 0 0\nv 1 0 0\0v 0 1 0\nv 0 1 0\nf 1 2 3\n", 40)},
      {"lone_carriage_return", "v 0 0 0\nv 1 0 0\rv 0 1 0\nv 0 1 0\nf 1 2 3\n"},
      {"nan", "v nan 0 0\n" + triangle + "f 2 3 4\n"},
      {"trailing_comment", "v 0 0 0 # origin\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"},
      {"second_object_name", "o a\no b\n" + triangle + "f 1 2 3\n"},
      {"only_vertices", triangle},
      {"tiny", "v 0 0 0\n"},
  };
  for (const auto& [name, text] : files) {
    EXPECT_FALSE(findObjFault(text)) << name;  // none malformed
    EXPECT_FALSE(readsTheSame(dir.write(std::string(name) + ".obj", text))) << name;
  }
}

// A file with a malformed statement is refused with its place (DESIGN.md §7 and §13: errors name
// the line and column), whether assimp would refuse it in other words ("OBJ: vertex index out of
// range" for a missing number, "Invalid face index" for an index 0) or repair it silently (read
// "1x" as 1, drop every normal for one index past them).
TEST(ObjFastParse, AMalformedStatementIsRefusedWithItsPlace) {
  TempDir dir;
  const std::string triangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  struct Case {
    const char* name;
    std::string text;
    std::size_t line, column;
    std::string what;
  };
  const Case cases[] = {
      {"past", triangle + "f 1 2 4\n", 4, 7, "vertex index 4 is past the file's 3 vertices"},
      {"second_face", triangle + "f 1 2 3\nf 3  2\t17\n", 5, 8,
       "vertex index 17 is past the file's 3 vertices"},
      {"crlf", "v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3\r\nf 1 2 3 5\r\n", 5, 9,
       "vertex index 5 is past the file's 3 vertices"},
      {"normals", triangle + "vn 0 0 1\nf 1//1 2//1 3//1\nf 2//1 12//1 3//1\n", 6, 8,
       "vertex index 12 is past the file's 3 vertices"},
      {"no_final_newline", triangle + "f 1 2 3\nf 4 2 3", 5, 3,
       "vertex index 4 is past the file's 3 vertices"},
      {"tiny", "f 1 2 3\n", 1, 3, "vertex index 1 is past the file's 0 vertices"},
      {"not_a_number", "v 0 0 0\nv 1 0 x\nv 0 1 0\nf 1 2 3\n", 2, 7, "'x' is not a number"},
      {"number_and_letter", "v 0 0 0\nv 1 0 1x\nv 0 1 0\nf 1 2 3\n", 2, 7, "'1x' is not a number"},
      {"decimal_comma", "v 0 0 0\nv 1,5 0 0\nv 0 1 0\nf 1 2 3\n", 2, 3, "'1,5' is not a number"},
      {"two_numbers", "v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n", 2, 6,
       "'v' needs 3 numbers, this line has 2"},
      {"index_zero", triangle + "f 0 1 2\n", 4, 3,
       "vertex index 0: OBJ indices count from 1 (or back from -1)"},
      {"relative_too_far", triangle + "f -1 -2 -4\n", 4, 9,
       "vertex index -4 reaches before the first vertex (3 are above it)"},
      {"normal_past", triangle + "vn 0 0 1\nf 1//1 2//1 3//2\n", 5, 16,
       "normal index 2 is past the file's 1 normal"},
      {"texture_past", triangle + "vt 0 0\nvt 1 0\nf 1/1 2/2 3/3\n", 6, 13,
       "texture coordinate index 3 is past the file's 2 texture coordinates"},
      {"corner_letter", triangle + "usemtl red\nf 1 2 x\n", 5, 7,
       "'x' is not a face corner (v, v/vt, v//vn or v/vt/vn, whole numbers)"},
      {"after_a_group", triangle + "g part\nf 1 2 3 # done\nf 2 3 9\n", 6, 7,
       "vertex index 9 is past the file's 3 vertices"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::optional<ObjFault> fault = findObjFault(c.text);
    ASSERT_TRUE(fault.has_value());
    EXPECT_EQ(fault->line, c.line);
    EXPECT_EQ(fault->column, c.column);
    EXPECT_EQ(fault->what, c.what);
    EXPECT_FALSE(parseSimpleObj(c.text));
    const fs::path path = dir.write(std::string(c.name) + ".obj", c.text);
    const ReferencedFileRule rule(path, path.parent_path());
    const std::string expected = locatedReason(*fault);
    try {
      importSimpleObj(path, rule);
      ADD_FAILURE() << "not refused";
    } catch (const MeshLoadError& e) {
      EXPECT_EQ(std::string(e.what()), expected);
    }
    // Through the reader, and as the quick look places it.
    const ChildAnswer answer = readInChild(path, nullptr);
    EXPECT_EQ(answer.refusal, expected);
    const std::optional<MeshErrorPlace> place = meshErrorPlace(answer.refusal);
    ASSERT_TRUE(place.has_value());
    EXPECT_EQ(place->line, static_cast<int>(c.line));
    EXPECT_EQ(place->column, static_cast<int>(c.column));
    EXPECT_EQ(place->reason, "invalid file: " + c.what);
  }
  EXPECT_FALSE(meshErrorPlace("invalid file: OBJ: vertex index out of range"));
  EXPECT_FALSE(meshErrorPlace("invalid file: line x, column 2: y"));
  EXPECT_FALSE(meshErrorPlace("no such file"));
}

TEST(ObjFastParse, ParsesNumbersWithAssimpsRoutine) {
  // assimp's float parse rounds the integer and the fraction apart: "1.00200814" becomes
  // 1.0020082, one unit in the last place above the nearest float, 1.00200808 (strtof's). The
  // fast path must give assimp's.
  const std::optional<SimpleObj> obj =
      parseSimpleObj("v 1.00200814 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\n");
  ASSERT_TRUE(obj.has_value());
  EXPECT_EQ(obj->positions[0], 1.0020082f);
  EXPECT_EQ(std::strtof("1.00200814", nullptr), 1.00200808f);
  EXPECT_EQ(obj->faceSizes, std::vector<std::uint32_t>{3});
  EXPECT_EQ(obj->vertexIndices, (std::vector<std::uint32_t>{0, 1, 2}));
  EXPECT_TRUE(obj->normalIndices.empty());
  EXPECT_EQ(obj->objectName, "defaultobject");
}

}  // namespace
}  // namespace glint::mesh_test
