#include "glint/factories/csg_factory.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <string_view>
#include <utility>
#include <vector>

#include "glint/factories/build_context.h"
#include "glint/factories/transform_reader.h"
#include "glint/readers/spelling.h"

namespace glint {

namespace {

constexpr std::array<std::string_view, 3> kOperations = {"union", "intersection", "difference"};
// The closed object types an operand may have, in the order messages list them.
constexpr std::array<std::string_view, 5> kOperandTypes = {"sphere", "box", "cylinder", "mesh",
                                                           "csg"};

std::optional<CsgOperation> readOperation(ParameterDictionary& params) {
  const auto name = params.text("operation", Presence::Required);
  if (!name) return std::nullopt;
  for (std::size_t k = 0; k < kOperations.size(); ++k) {
    if (name->value == kOperations[k]) return static_cast<CsgOperation>(k);
  }
  params.error(name->where, fmt::format("{}.operation: expected union, intersection or "
                                        "difference, got {}{}",
                                        params.names().path, quoteForMessage(name->value),
                                        didYouMean(name->value, kOperations)));
  return std::nullopt;
}

// One mesh of a file's parts (all of them, whatever their materials): positions and triangles.
std::shared_ptr<const CsgMesh> closedMesh(const MeshFile& file) {
  std::vector<Point3> positions;
  std::vector<std::uint32_t> indices;
  for (const TriangleMesh& part : file.parts) {
    const auto offset = static_cast<std::uint32_t>(positions.size());
    positions.insert(positions.end(), part.positions.begin(), part.positions.end());
    for (const std::uint32_t index : part.indices) indices.push_back(offset + index);
  }
  return CsgMesh::make(std::move(positions), std::move(indices));
}

// Where a ShapeError about `parameter` is reported: that key's value, or the operand.
ValueId placeOf(ParameterDictionary& params, const std::string& parameter) {
  if (params.has(parameter)) return params.find(parameter)->where;
  if (parameter == "file" && params.has("positions")) return params.find("positions")->where;
  return params.place();
}

// Operand `index` of a csg: its own csg (one level deeper) or a closed solid.
std::optional<Csg> readOperand(const ValueReader& reader, ValueId value, ValueId where,
                               const std::string& path, std::uint32_t material, Color emission,
                               CsgServices& services, int depth) {
  const ValueTree& tree = reader.tree();
  if (!tree.isMap(value)) {
    reader.error(where, fmt::format("{}: expected a mapping with a 'type' ({}), got {}", path,
                                    fmt::join(kOperandTypes, ", "), reader.describe(value)));
    return std::nullopt;
  }
  ParameterDictionary params(reader, value, {"in " + path, path, path});
  params.declareHidden("type");
  const auto type = params.text("type", Presence::Required);
  const ObjectFactory* factory = nullptr;
  bool closed = false;
  if (type) {
    factory = findObjectFactory(type->value);
    closed =
        std::find(kOperandTypes.begin(), kOperandTypes.end(), type->value) != kOperandTypes.end();
    if (closed) {
      // Stays null for csg, which this file reads.
    } else if (factory != nullptr) {
      params.error(type->where,
                   fmt::format("{}.type: {} is not a closed shape; a csg combines closed shapes "
                               "({})",
                               path, quoteForMessage(type->value), fmt::join(kOperandTypes, ", ")));
    } else {
      params.error(type->where,
                   fmt::format("{}.type: unknown operand type {}; expected one of: "
                               "{}{}",
                               path, quoteForMessage(type->value), fmt::join(kOperandTypes, ", "),
                               didYouMean(type->value, kOperandTypes)));
    }
  }
  if (!type || !closed) {
    // Keys cannot be checked without a type; duplicates still are (the constructor did).
    params.markUsed(params.keys());
    params.finish();
    return std::nullopt;
  }
  const bool isCsg = type->value == "csg";
  params.declare(isCsg ? kCsgKeys : factory->keys);
  params.declare({"material", "emission", "transform"});
  if (const auto own = services.material(params, path)) {
    material = own->index;
    if (services.emissionTexture) emission = Color();
    // The operand's material's emission, unless the operand gives its own.
    if (own->emission) emission = *own->emission;
  }
  if (params.has("emission")) {
    if (const auto own = readCoefficient(params, "emission", services.encoding)) emission = *own;
  }
  const TransformResult transform = readTransform(params, path);
  std::optional<Csg> result;
  if (isCsg) {
    if (depth + 1 > kMaxCsgDepth) {
      params.error(params.place(),
                   fmt::format("{}: csgs may be nested at most {} deep", path, kMaxCsgDepth));
      params.markUsed(params.keys());
      params.finish();
      return std::nullopt;
    }
    result = readCsg(params, path, material, emission, services, depth + 1);
    params.finish();
    if (!result || !transform.ok || params.errors() != 0) return std::nullopt;
    if (transform.worldFromObject) {
      try {
        result = transformCsg(*result, *transform.worldFromObject);
      } catch (const ShapeError& error) {
        params.error(placeOf(params, error.parameter()), fmt::format("{}.{}", path, error.what()));
        return std::nullopt;
      }
    }
    return result;
  }
  std::optional<ObjectGeometry> geometry;
  try {
    geometry = factory->read(params);
    if (geometry && transform.ok) {
      CsgSolid solid;
      if (const auto* request = std::get_if<MeshRequest>(&*geometry)) {
        const std::shared_ptr<const MeshFile> file =
            params.errors() == 0 ? services.mesh(params, *request) : nullptr;
        if (file == nullptr) {
          params.finish();
          return std::nullopt;
        }
        solid = closedMesh(*file);
      } else {
        const Shape& shape = std::get<Shape>(*geometry);
        if (const auto* s = std::get_if<Sphere>(&shape)) solid = *s;
        if (const auto* s = std::get_if<Box>(&shape)) solid = *s;
        if (const auto* s = std::get_if<Cylinder>(&shape)) solid = *s;
      }
      result = makeCsgSolid(std::move(solid), transform.worldFromObject, material, emission);
    }
  } catch (const ShapeError& error) {
    // "csg.operands[0] (sphere).radius must be > 0, got ..." at that key; a mesh that is not
    // closed at its file (or inline positions).
    const bool atKey = error.parameter() != "file" && params.has(error.parameter());
    params.error(placeOf(params, error.parameter()),
                 fmt::format("{} ({}){}{}", path, type->value, atKey ? "." : ": ", error.what()));
    result.reset();
  }
  params.finish();
  if (params.errors() != 0) return std::nullopt;
  return result;
}

}  // namespace

std::optional<Csg> readCsg(ParameterDictionary& params, const std::string& path,
                           std::uint32_t material, const Color& emission, CsgServices& services,
                           int depth) {
  const std::optional<CsgOperation> operation = readOperation(params);
  const auto operands = params.find("operands");
  if (!operands) {
    params.requireKey("operands");
    return std::nullopt;
  }
  const ValueReader& reader = params.reader();
  const ValueTree& tree = reader.tree();
  if (!tree.isList(operands->value) || tree.size(operands->value) < 2) {
    params.error(operands->where,
                 fmt::format("{}.operands: expected a list of at least two objects, got {}", path,
                             reader.describe(operands->value)));
    return std::nullopt;
  }
  std::vector<Csg> built;
  bool ok = true;
  for (std::size_t i = 0; i < tree.size(operands->value); ++i) {
    const std::string itemPath = fmt::format("{}.operands[{}]", path, i);
    std::optional<Csg> operand = readOperand(reader, tree.item(operands->value, i),
                                             reader.itemPlace(operands->value, operands->where, i),
                                             itemPath, material, emission, services, depth);
    if (!operand) {
      ok = false;
      continue;
    }
    built.push_back(std::move(*operand));
  }
  if (!ok || !operation) return std::nullopt;
  try {
    return combineCsg(*operation, built);
  } catch (const ShapeError& error) {
    params.error(operands->where, fmt::format("{}.operands: {}", path, error.what()));
    return std::nullopt;
  }
}

}  // namespace glint
