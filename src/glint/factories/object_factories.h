// The object family: one factory per object `type` (DESIGN.md §5, §8), in one table. A factory
// reads its own geometry keys from the object's parameters, checks them once, and returns the
// geometry; the scene builder reads the keys every object shares (material, emission, transform)
// and commits the object. Adding a shape: its geometry (geometry/shape.h), its factory function
// below, one row in objectFactories() — nothing else.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "glint/geometry/shape.h"
#include "glint/mesh/mesh_file.h"
#include "glint/readers/parameter_dictionary.h"

namespace glint {

// A mesh object before its file is read: the path as written (relative paths start at the scene
// file's folder) and whether its vertex normals are interpolated. An inline mesh (positions,
// indices, ...) has no file: its contents are built already.
struct MeshRequest {
  std::string file;
  ValueId fileWhere = kNoValue;
  bool smooth = true;
  std::shared_ptr<const MeshFile> contents;  // an inline mesh; null for a file
};

using ObjectGeometry = std::variant<Shape, MeshRequest>;

struct ObjectFactory {
  std::string_view type;
  // Its geometry keys, in the order the documentation and messages list them.
  std::vector<std::string_view> keys;
  // Reads the geometry keys; nullopt when one is missing or wrong (already reported). May throw
  // ShapeError for a degenerate shape, naming the parameter at fault.
  std::optional<ObjectGeometry> (*read)(ParameterDictionary& params) = nullptr;
};

// The built-in object types, in the order messages list them.
const std::vector<ObjectFactory>& objectFactories();

// The factory of `type` among `extra` (first) and the built-in ones, or nullptr.
const ObjectFactory* findObjectFactory(std::string_view type,
                                       const std::vector<ObjectFactory>& extra = {});

// The factories of the shapes an area light may take (rectangle, disk, sphere), in that order.
std::vector<const ObjectFactory*> areaShapeFactories();

}  // namespace glint
