// The Tachyon reader's objects: SPHERE, FCYLINDER, CYLINDER, RING, PLANE and BOX as glint objects;
// TRI, STRI, VCSTRI and VERTEXARRAY as triangles of inline meshes (tachyon_reader.h gives the
// mapping). Internal to the Tachyon reader.
#pragma once

#include <array>
#include <string>

#include "glint/core/vec.h"
#include "glint/readers/mesh_collector.h"
#include "glint/readers/tachyon_texture.h"

namespace glint::tachyon {

class Geometry {
 public:
  // `transVmd`: the scene's SHADER_MODE TRANS_VMD, as it stands when each object is read.
  Geometry(Input& in, SceneEmitter& out, Textures& textures, const bool& transVmd)
      : in_(in), out_(out), textures_(textures), transVmd_(transVmd) {}
  // SPHERE, FCYLINDER, CYLINDER, RING, PLANE or BOX (`word`, upper case) after its keyword.
  void shape(const Token& t, const std::string& word);
  // TRI, STRI or VCSTRI.
  void triangle(const Token& t, const std::string& word);
  void vertexArray(const Token& t);
  // The meshes of every triangle read, as object entities.
  void emitMeshes() { meshes_.emit(out_); }

 private:
  // A vertex's numbers added to the tree as they are read (a mesh holds them), with their values.
  struct VertexData {
    CollectedVertex ids;
    Vec3 position, normal;
  };
  std::array<ValueId, 3> addTriple(const Triple& t);
  void addTriangle(const std::string& material, VertexData a, VertexData b, VertexData c,
                   const TextPosition& at);

  Input& in_;
  SceneEmitter& out_;
  Textures& textures_;
  const bool& transVmd_;
  MeshCollector meshes_;
};

}  // namespace glint::tachyon
