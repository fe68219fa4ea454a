// Radiosity export: every format read back by an independent reader (OpenMesh and a minimal PLY
// parser, tinyobjloader, tinygltf), quantity selection, and the failure cases (unsupported
// extension, missing folder, no temporaries left, existing files kept); the exported elements
// checked at random points of the input (check_element_colours) against a scan of every element.

#include "radiosity/bake/export.h"

#include <unistd.h>

#include <gtest/gtest.h>
#include <tiny_gltf.h>
#include <tiny_obj_loader.h>
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "radiosity/bake/check.h"
#include "raytrace_core/util/closest_point.h"
#include "raytrace_core/util/error.h"
#include "raytrace_core/io/scene_io.h"
#include "tests/support/test_scenes.h"

namespace gilt::radiosity {
using namespace mesh;
using namespace solver;
using namespace bake;
namespace {

namespace fs = std::filesystem;
using rc::InputError;

// --- Readers --------------------------------------------------------------------------------

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

/// A binary little-endian PLY with a vertex element of scalar properties and a face element of
/// vertex_indices lists, read exactly. OpenMesh's reader cannot check float colours: it turns
/// them into bytes on the way in.
struct PlyData {
  std::vector<std::string> vertex_types, vertex_names;
  std::vector<std::vector<double>> vertices;  // values in header order
  std::vector<std::vector<int>> faces;

  double value(size_t v, const std::string& name) const {
    const auto it = std::find(vertex_names.begin(), vertex_names.end(), name);
    return vertices.at(v).at(static_cast<size_t>(it - vertex_names.begin()));
  }
};

template <class T>
T take(const std::string& bytes, size_t& at) {
  T value;
  if (at + sizeof(T) > bytes.size()) throw std::runtime_error("PLY body too short");
  std::memcpy(&value, bytes.data() + at, sizeof(T));
  at += sizeof(T);
  return value;
}

double take_scalar(const std::string& type, const std::string& bytes, size_t& at) {
  if (type == "float") return take<float>(bytes, at);
  if (type == "uchar") return take<uint8_t>(bytes, at);
  if (type == "int") return take<int32_t>(bytes, at);
  throw std::runtime_error("unexpected PLY type " + type);
}

PlyData read_ply(const fs::path& path) {
  const std::string bytes = read_text(path);
  const size_t end = bytes.find("end_header\n");
  if (bytes.rfind("ply\n", 0) != 0 || end == std::string::npos) throw std::runtime_error("not a PLY file");
  std::istringstream header(bytes.substr(0, end));
  PlyData ply;
  size_t vertex_count = 0, face_count = 0;
  std::string element, count_type, index_type;
  for (std::string line; std::getline(header, line);) {
    std::istringstream words(line);
    std::string word;
    words >> word;
    if (word == "format") {
      std::string format;
      words >> format;
      if (format != "binary_little_endian") throw std::runtime_error("format " + format);
    } else if (word == "element") {
      words >> element;
      (element == "vertex" ? vertex_count : face_count) = std::stoul([&] {
        std::string n;
        words >> n;
        return n;
      }());
    } else if (word == "property" && element == "vertex") {
      std::string type, name;
      words >> type >> name;
      ply.vertex_types.push_back(type);
      ply.vertex_names.push_back(name);
    } else if (word == "property" && element == "face") {
      std::string list, name;
      words >> list >> count_type >> index_type >> name;
      if (list != "list" || name != "vertex_indices") throw std::runtime_error("face property " + line);
    }
  }
  size_t at = end + std::strlen("end_header\n");
  for (size_t v = 0; v < vertex_count; ++v) {
    std::vector<double> values;
    for (const std::string& type : ply.vertex_types) values.push_back(take_scalar(type, bytes, at));
    ply.vertices.push_back(values);
  }
  for (size_t f = 0; f < face_count; ++f) {
    const int n = static_cast<int>(take_scalar(count_type, bytes, at));
    std::vector<int> face;
    for (int k = 0; k < n; ++k) face.push_back(static_cast<int>(take_scalar(index_type, bytes, at)));
    ply.faces.push_back(face);
  }
  if (at != bytes.size()) throw std::runtime_error("trailing bytes after the PLY body");
  return ply;
}

/// The items of a float or uint32 accessor, as floats or integers.
template <class T>
std::vector<T> accessor_items(const tinygltf::Model& model, int index, int components) {
  const tinygltf::Accessor& accessor = model.accessors.at(index);
  const tinygltf::BufferView& view = model.bufferViews.at(accessor.bufferView);
  const tinygltf::Buffer& buffer = model.buffers.at(view.buffer);
  const size_t item = sizeof(T) * components;
  const size_t stride = view.byteStride ? view.byteStride : item;
  std::vector<T> items(accessor.count * components);
  for (size_t i = 0; i < accessor.count; ++i) {
    std::memcpy(&items[i * components],
                buffer.data.data() + view.byteOffset + accessor.byteOffset + i * stride, item);
  }
  return items;
}

/// OpenMesh reads colours into floats c/255 here; byte colours (OpenMesh's default) trip a
/// -Wmaybe-uninitialized warning inside its headers.
struct ReadTraits : OpenMesh::DefaultTraits {
  using Color = OpenMesh::Vec4f;
};
using ReadMesh = OpenMesh::TriMesh_ArrayKernelT<ReadTraits>;

// --- The solution ---------------------------------------------------------------------------

/// sRGB encoding, written out again here so the test does not share the exporter's code.
double srgb(double linear) {
  return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

/// A unit square of a diffuse wall (two elements) under an emissive triangle facing down, plus a
/// material no element uses. Colours are chosen to need all nine digits.
class ExportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    dir_ = fs::temp_directory_path() / ("gilt_test_export_" + std::to_string(::getpid()) + "_" + test);
    fs::remove_all(dir_);
    fs::create_directories(dir_);

    scene_.name = "test room";
    scene_.materials.push_back(rc::scene::Material::make_diffuse("white wall", rc::Rgb(0.7f, 0.6f, 0.5f)));
    scene_.materials.push_back(
        rc::scene::Material::make_emitter("lamp", rc::Rgb(10.0f, 8.0f, 6.0f), rc::Rgb(0.5f)));
    scene_.materials.push_back(
        rc::scene::Material::make_glossy("unused", rc::Rgb(0.2f), rc::Rgb(0.3f), 50.0f));
    rc::scene::TriangleMesh wall;
    wall.name = "wall";
    wall.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    wall.indices = {0, 1, 2, 0, 2, 3};
    wall.material = 0;
    rc::scene::TriangleMesh lamp;
    lamp.name = "lamp";
    lamp.positions = {{0.25f, 0.25f, 1}, {0.5f, 0.75f, 1}, {0.75f, 0.25f, 1}};
    lamp.indices = {0, 1, 2};
    lamp.material = 1;
    scene_.meshes = {wall, lamp};
    scene_.commit();

    RadiosityMesh& mesh = solution_.mesh;
    mesh.positions = {{0, 0, 0},         {1, 0, 0},        {1, 1, 0},        {0, 1, 0},
                      {0.25f, 0.25f, 1}, {0.5f, 0.75f, 1}, {0.75f, 0.25f, 1}};
    mesh.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, -1}, {0, 0, -1}, {0, 0, -1}};
    mesh.vertex_material = {0, 0, 0, 0, 1, 1, 1};
    mesh.elements = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}};
    mesh.element_material = {0, 0, 1};
    mesh.element_surface = {0, 0, 1};
    mesh.element_normal = {{0, 0, 1}, {0, 0, 1}, {0, 0, -1}};
    mesh.element_area = {0.5f, 0.5f, 0.125f};
    solution_.vertex_irradiance = {
        {0.1f, 0.2f, 0.3f},    {1.0f / 3.0f, 2.5f, 1e-7f}, {0.0f, 123.456f, 7e-3f}, {0.9999f, 0.5f, 0.25f},
        {0.01f, 0.02f, 0.03f}, {1.1f, 2.2f, 3.3f},         {4e-5f, 5e-4f, 6e-3f}};
    solution_.vertex_radiosity.resize(mesh.vertex_count());
    for (size_t v = 0; v < mesh.vertex_count(); ++v) {
      const rc::scene::Material& m = scene_.materials[mesh.vertex_material[v]];
      solution_.vertex_radiosity[v] = m.emission * rc::kPi + m.albedo * solution_.vertex_irradiance[v];
    }
    for (const auto& e : mesh.elements) {
      solution_.element_radiosity.push_back((solution_.vertex_radiosity[e[0]] +
                                             solution_.vertex_radiosity[e[1]] +
                                             solution_.vertex_radiosity[e[2]]) /
                                            3.0f);
    }
  }

  void TearDown() override { fs::remove_all(dir_); }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  /// Names of everything in the test folder, sorted.
  std::vector<std::string> files() const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir_)) names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }

  std::vector<rc::Rgb> expected(Quantity quantity) const {
    std::vector<rc::Rgb> colours;
    for (size_t v = 0; v < solution_.mesh.vertex_count(); ++v) {
      colours.push_back(quantity == Quantity::radiance     ? solution_.vertex_radiance(v)
                        : quantity == Quantity::irradiance ? solution_.vertex_irradiance[v]
                                                           : solution_.vertex_radiosity[v]);
    }
    return colours;
  }

  /// Index of the mesh vertex at exactly this position (the test positions are distinct).
  size_t vertex_at(float x, float y, float z) const {
    const auto& p = solution_.mesh.positions;
    const auto it = std::find(p.begin(), p.end(), Vec3(x, y, z));
    EXPECT_NE(it, p.end()) << "no vertex at " << x << " " << y << " " << z;
    return static_cast<size_t>(it - p.begin());
  }

  void check_gltf(const std::string& file, bool binary);

  fs::path dir_;
  rc::scene::Scene scene_;
  Solution solution_;
};

// --- Tests ----------------------------------------------------------------------------------

TEST(ParseQuantity, KnowsTheThreeNames) {
  EXPECT_EQ(parse_quantity("radiance"), Quantity::radiance);
  EXPECT_EQ(parse_quantity("irradiance"), Quantity::irradiance);
  EXPECT_EQ(parse_quantity("radiosity"), Quantity::radiosity);
  try {
    parse_quantity("Radiance");
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "unknown quantity 'Radiance' (expected radiance, irradiance or radiosity)");
  }
}

TEST_F(ExportTest, PlyFloatColoursRoundTripExactly) {
  ExportSettings linear;
  linear.linear_float = true;
  write_solution(path("out.ply"), scene_, solution_, linear);
  const PlyData ply = read_ply(path("out.ply"));
  EXPECT_EQ(ply.vertex_names,
            (std::vector<std::string>{"x", "y", "z", "nx", "ny", "nz", "red", "green", "blue"}));
  EXPECT_EQ(ply.vertex_types, std::vector<std::string>(9, "float"));
  const RadiosityMesh& mesh = solution_.mesh;
  const auto colours = expected(Quantity::radiance);
  ASSERT_EQ(ply.vertices.size(), mesh.vertex_count());
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    EXPECT_EQ(ply.value(v, "x"), mesh.positions[v].x);
    EXPECT_EQ(ply.value(v, "y"), mesh.positions[v].y);
    EXPECT_EQ(ply.value(v, "z"), mesh.positions[v].z);
    EXPECT_EQ(ply.value(v, "nz"), mesh.normals[v].z);
    EXPECT_EQ(ply.value(v, "red"), colours[v].r) << v;
    EXPECT_EQ(ply.value(v, "green"), colours[v].g) << v;
    EXPECT_EQ(ply.value(v, "blue"), colours[v].b) << v;
  }
  ASSERT_EQ(ply.faces.size(), mesh.element_count());
  for (size_t e = 0; e < mesh.element_count(); ++e) {
    EXPECT_EQ(ply.faces[e], (std::vector<int>{int(mesh.elements[e][0]), int(mesh.elements[e][1]),
                                              int(mesh.elements[e][2])}));
  }

  // OpenMesh reads the same geometry back (its reader turns float colours into bytes, so the
  // colours were checked above).
  ReadMesh read;
  read.request_vertex_normals();
  OpenMesh::IO::Options options = OpenMesh::IO::Options::VertexNormal;
  ASSERT_TRUE(OpenMesh::IO::read_mesh(read, path("out.ply"), options));
  EXPECT_TRUE(options.check(OpenMesh::IO::Options::VertexNormal));
  ASSERT_EQ(read.n_vertices(), mesh.vertex_count());
  ASSERT_EQ(read.n_faces(), mesh.element_count());
  for (const auto v : read.vertices()) {
    const auto p = read.point(v);
    EXPECT_EQ(Vec3(p[0], p[1], p[2]), mesh.positions[v.idx()]);
    const auto n = read.normal(v);
    EXPECT_EQ(Vec3(n[0], n[1], n[2]), mesh.normals[v.idx()]);
  }
}

TEST_F(ExportTest, PlySrgb8IsWithinHalfAStep) {
  ExportSettings settings;
  settings.quantity = Quantity::irradiance;
  settings.srgb8 = true;
  settings.exposure = 1.5f;
  write_solution(path("out.ply"), scene_, solution_, settings);
  const PlyData ply = read_ply(path("out.ply"));
  EXPECT_EQ(std::vector<std::string>(ply.vertex_types.begin() + 6, ply.vertex_types.end()),
            std::vector<std::string>(3, "uchar"));

  ReadMesh read;
  read.request_vertex_colors();
  OpenMesh::IO::Options options = OpenMesh::IO::Options::VertexColor;
  ASSERT_TRUE(OpenMesh::IO::read_mesh(read, path("out.ply"), options));
  ASSERT_TRUE(options.vertex_has_color());
  ASSERT_EQ(read.n_vertices(), solution_.mesh.vertex_count());
  const auto colours = expected(Quantity::irradiance);
  const double scale = std::exp2(1.5);
  for (const auto v : read.vertices()) {
    for (int c = 0; c < 3; ++c) {
      const double want = std::clamp(srgb(colours[v.idx()][c] * scale), 0.0, 1.0);
      const long code = std::lround(read.color(v)[c] * 255.0f);
      EXPECT_EQ(code, static_cast<long>(ply.value(v.idx(), ply.vertex_names[6 + c])));
      EXPECT_NEAR(code / 255.0, want, 0.5 / 255.0 + 1e-6) << "vertex " << v.idx() << " channel " << c;
    }
  }
  EXPECT_EQ(ply.value(2, "green"), 255);  // 123.456 clamps
  EXPECT_EQ(ply.value(2, "red"), 0);
}

TEST_F(ExportTest, QuantityChoosesTheColour) {
  // By default the PLY holds display colours (8-bit sRGB after exposure) and the quantity itself
  // in <quantity>_red/_green/_blue, bit-exact.
  for (const Quantity quantity : {Quantity::radiance, Quantity::irradiance, Quantity::radiosity}) {
    ExportSettings settings;
    settings.quantity = quantity;
    settings.exposure = 3.0f;
    write_solution(path("out.ply"), scene_, solution_, settings);
    const PlyData ply = read_ply(path("out.ply"));
    const std::string name = to_string(quantity);
    EXPECT_EQ(ply.vertex_names, (std::vector<std::string>{"x", "y", "z", "nx", "ny", "nz", "red", "green", "blue",
                                                          name + "_red", name + "_green", name + "_blue"}));
    EXPECT_EQ(std::vector<std::string>(ply.vertex_types.begin() + 6, ply.vertex_types.begin() + 9),
              std::vector<std::string>(3, "uchar"));
    const auto colours = expected(quantity);
    for (size_t v = 0; v < colours.size(); ++v) {
      EXPECT_EQ(ply.value(v, name + "_red"), colours[v].r);
      EXPECT_EQ(ply.value(v, name + "_green"), colours[v].g);
      EXPECT_EQ(ply.value(v, name + "_blue"), colours[v].b);
      for (int c = 0; c < 3; ++c)
        EXPECT_EQ(ply.value(v, ply.vertex_names[6 + size_t(c)]), to_srgb8(colours[v][c], 8.0f)) << v;
    }
  }
}

TEST_F(ExportTest, ObjRoundTripsThroughTinyobjloader) {
  ExportSettings settings;
  settings.quantity = Quantity::radiosity;
  settings.linear_float = true;  // the values themselves, bit-exact; display colours below
  write_solution(path("out.obj"), scene_, solution_, settings);
  EXPECT_EQ(files(), (std::vector<std::string>{"out.mtl", "out.obj"}));

  tinyobj::ObjReader reader;
  tinyobj::ObjReaderConfig config;
  config.triangulate = false;
  ASSERT_TRUE(reader.ParseFromFile(path("out.obj"), config)) << reader.Error();
  EXPECT_EQ(reader.Warning(), "");
  const tinyobj::attrib_t& attrib = reader.GetAttrib();
  const RadiosityMesh& mesh = solution_.mesh;
  const auto colours = expected(Quantity::radiosity);
  ASSERT_EQ(attrib.vertices.size(), 3 * mesh.vertex_count());
  ASSERT_EQ(attrib.colors.size(), 3 * mesh.vertex_count());
  ASSERT_EQ(attrib.normals.size(), 3 * mesh.vertex_count());
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(attrib.vertices[3 * v + c], mesh.positions[v][c]);
      EXPECT_EQ(attrib.normals[3 * v + c], mesh.normals[v][c]);
      EXPECT_EQ(attrib.colors[3 * v + c], colours[v][c]) << "vertex " << v << " channel " << c;
    }
  }

  const auto& materials = reader.GetMaterials();
  ASSERT_EQ(materials.size(), 2u);  // the unused one is left out
  EXPECT_EQ(materials[0].name, "white_wall");
  EXPECT_EQ(materials[1].name, "lamp");
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(materials[0].diffuse[c], scene_.materials[0].albedo[c]);
    EXPECT_EQ(materials[0].emission[c], 0.0f);
    EXPECT_EQ(materials[1].diffuse[c], scene_.materials[1].albedo[c]);
    EXPECT_EQ(materials[1].emission[c], scene_.materials[1].emission[c]);
    EXPECT_EQ(materials[1].specular[c], 0.0f);
  }
  EXPECT_EQ(materials[0].illum, 1);
  EXPECT_EQ(materials[0].dissolve, 1.0f);
  EXPECT_EQ(materials[0].ior, 1.5f);

  std::vector<std::array<int, 4>> faces;  // vertices and material
  for (const tinyobj::shape_t& shape : reader.GetShapes()) {
    size_t corner = 0;
    for (size_t f = 0; f < shape.mesh.num_face_vertices.size(); ++f) {
      ASSERT_EQ(shape.mesh.num_face_vertices[f], 3);
      std::array<int, 4> face{};
      for (int k = 0; k < 3; ++k) {
        const tinyobj::index_t& index = shape.mesh.indices[corner++];
        EXPECT_EQ(index.vertex_index, index.normal_index);
        EXPECT_EQ(index.texcoord_index, -1);
        face[k] = index.vertex_index;
      }
      face[3] = shape.mesh.material_ids[f];
      faces.push_back(face);
    }
  }
  const std::string mtl_name[] = {"white_wall", "lamp"};
  ASSERT_EQ(faces.size(), mesh.element_count());
  for (size_t e = 0; e < mesh.element_count(); ++e) {
    EXPECT_EQ(faces[e][0], int(mesh.elements[e][0]));
    EXPECT_EQ(faces[e][1], int(mesh.elements[e][1]));
    EXPECT_EQ(faces[e][2], int(mesh.elements[e][2]));
    EXPECT_EQ(materials.at(faces[e][3]).name, mtl_name[mesh.element_material[e]]);
  }
}

void ExportTest::check_gltf(const std::string& file, bool binary) {
  write_solution(path(file), scene_, solution_, {});
  EXPECT_EQ(files(), std::vector<std::string>{file});  // a .gltf embeds its buffer

  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string error, warning;
  const bool ok = binary ? loader.LoadBinaryFromFile(&model, &error, &warning, path(file))
                         : loader.LoadASCIIFromFile(&model, &error, &warning, path(file));
  ASSERT_TRUE(ok) << error;
  EXPECT_EQ(warning, "");
  ASSERT_EQ(model.meshes.size(), 1u);
  const auto& primitives = model.meshes[0].primitives;
  ASSERT_EQ(primitives.size(), 2u);  // one per used material
  ASSERT_EQ(model.materials.size(), 2u);

  const auto colours = expected(Quantity::radiance);
  const RadiosityMesh& mesh = solution_.mesh;
  std::vector<std::array<size_t, 4>> triangles;  // mesh vertices and scene material
  const uint32_t scene_material[] = {0, 1};
  for (const tinygltf::Primitive& primitive : primitives) {
    EXPECT_EQ(primitive.mode, TINYGLTF_MODE_TRIANGLES);
    const auto& color = model.accessors.at(primitive.attributes.at("COLOR_0"));
    EXPECT_EQ(color.type, TINYGLTF_TYPE_VEC3);
    EXPECT_EQ(color.componentType, TINYGLTF_COMPONENT_TYPE_FLOAT);
    EXPECT_EQ(model.accessors.at(primitive.indices).componentType, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT);
    EXPECT_EQ(model.accessors.at(primitive.attributes.at("POSITION")).minValues.size(), 3u);
    const auto positions = accessor_items<float>(model, primitive.attributes.at("POSITION"), 3);
    const auto normals = accessor_items<float>(model, primitive.attributes.at("NORMAL"), 3);
    const auto rgb = accessor_items<float>(model, primitive.attributes.at("COLOR_0"), 3);
    const auto hdr = accessor_items<float>(model, primitive.attributes.at("_RADIANCE"), 3);
    const auto indices = accessor_items<uint32_t>(model, primitive.indices, 1);
    std::vector<size_t> original;
    for (size_t i = 0; i < positions.size() / 3; ++i) {
      const size_t v = vertex_at(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]);
      original.push_back(v);
      EXPECT_EQ(Vec3(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]), mesh.normals[v]);
      for (int c = 0; c < 3; ++c) {
        // COLOR_0 is display-referred, clamped to [0, 1] as glTF requires; _RADIANCE holds the
        // value itself, bit-exact.
        EXPECT_EQ(rgb[3 * i + size_t(c)], std::clamp(colours[v][c], 0.0f, 1.0f)) << "vertex " << v;
        EXPECT_EQ(hdr[3 * i + size_t(c)], colours[v][c]) << "vertex " << v;
      }
    }
    for (size_t i = 0; i + 2 < indices.size(); i += 3) {
      triangles.push_back({original.at(indices[i]), original.at(indices[i + 1]), original.at(indices[i + 2]),
                           scene_material[primitive.material]});
    }
  }
  ASSERT_EQ(triangles.size(), mesh.element_count());
  for (size_t e = 0; e < mesh.element_count(); ++e) {
    EXPECT_EQ(triangles[e], (std::array<size_t, 4>{mesh.elements[e][0], mesh.elements[e][1],
                                                   mesh.elements[e][2], mesh.element_material[e]}));
  }

  const tinygltf::Material& wall = model.materials[0];
  EXPECT_EQ(wall.name, "white_wall");
  EXPECT_EQ(wall.pbrMetallicRoughness.baseColorFactor, (std::vector<double>{0.7f, 0.6f, 0.5f, 1.0}));
  EXPECT_EQ(wall.pbrMetallicRoughness.metallicFactor, 0.0);
  EXPECT_EQ(wall.pbrMetallicRoughness.roughnessFactor, 1.0);
  EXPECT_EQ(wall.emissiveFactor, (std::vector<double>{0.0, 0.0, 0.0}));
  // Lambertian: the specification's BRDF without its specular layer.
  ASSERT_EQ(wall.extensions.size(), 1u);
  EXPECT_EQ(wall.extensions.at("KHR_materials_specular").Get("specularFactor").GetNumberAsDouble(), 0.0);
  const tinygltf::Material& lamp = model.materials[1];
  EXPECT_EQ(lamp.pbrMetallicRoughness.baseColorFactor, (std::vector<double>{0.5, 0.5, 0.5, 1.0}));
  ASSERT_EQ(lamp.extensions.count("KHR_materials_emissive_strength"), 1u);
  const double strength =
      lamp.extensions.at("KHR_materials_emissive_strength").Get("emissiveStrength").GetNumberAsDouble();
  EXPECT_EQ(strength, 10.0);
  ASSERT_EQ(lamp.emissiveFactor.size(), 3u);
  for (int c = 0; c < 3; ++c) {
    EXPECT_LE(lamp.emissiveFactor[c], 1.0);
    EXPECT_NEAR(lamp.emissiveFactor[c] * strength, scene_.materials[1].emission[c], 1e-6);
  }
  EXPECT_NE(
      std::find(model.extensionsUsed.begin(), model.extensionsUsed.end(), "KHR_materials_emissive_strength"),
      model.extensionsUsed.end());
}

TEST_F(ExportTest, ObjColoursAreDisplayValuesByDefault) {
  // Blender's and MeshLab's OBJ importers read `v x y z r g b` as display colours: the default is
  // the quantity × 2^exposure, clamped and sRGB-encoded (to_srgb), to nine digits.
  ExportSettings settings;
  settings.exposure = -1.0f;
  write_solution(path("out.obj"), scene_, solution_, settings);
  tinyobj::ObjReader reader;
  ASSERT_TRUE(reader.ParseFromFile(path("out.obj"), tinyobj::ObjReaderConfig())) << reader.Error();
  const auto colours = expected(Quantity::radiance);
  const tinyobj::attrib_t& attrib = reader.GetAttrib();
  ASSERT_EQ(attrib.colors.size(), 3 * colours.size());
  for (size_t v = 0; v < colours.size(); ++v)
    for (int c = 0; c < 3; ++c) {
      const float display = attrib.colors[3 * v + size_t(c)];
      EXPECT_GE(display, 0.0f);
      EXPECT_LE(display, 1.0f);
      EXPECT_NEAR(display, to_srgb(colours[v][c], 0.5f), 1e-6f) << "vertex " << v << " channel " << c;
    }
}

TEST_F(ExportTest, GltfRoundTripsThroughTinygltf) { check_gltf("out.gltf", false); }

TEST_F(ExportTest, GlbRoundTripsThroughTinygltf) { check_gltf("out.glb", true); }

TEST_F(ExportTest, UnsupportedExtensionWritesNothing) {
  for (const std::string name : {"out.stl", "out", "out.ply.bak"}) {
    try {
      write_solution(path(name), scene_, solution_, {});
      ADD_FAILURE() << name << ": no InputError";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path(name)), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("unsupported"), std::string::npos) << e.what();
    }
  }
  EXPECT_TRUE(files().empty());
  write_solution(path("upper.PLY"), scene_, solution_, {});  // extensions are case-insensitive
  EXPECT_EQ(files(), std::vector<std::string>{"upper.PLY"});
}

TEST_F(ExportTest, MissingFolderIsAnInputError) {
  for (const std::string name :
       {"missing/out.ply", "missing/out.obj", "missing/out.gltf", "missing/out.glb"}) {
    try {
      write_solution(path(name), scene_, solution_, {});
      ADD_FAILURE() << name << ": no InputError";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path(name)), std::string::npos) << e.what();
    }
  }
  EXPECT_TRUE(files().empty());
}

TEST_F(ExportTest, NoTemporaryFilesLeft) {
  for (int round = 0; round < 2; ++round) {  // the second round replaces existing files
    for (const char* name : {"out.ply", "out.obj", "out.gltf", "out.glb"}) {
      write_solution(path(name), scene_, solution_, {});
    }
  }
  EXPECT_EQ(files(), (std::vector<std::string>{"out.glb", "out.gltf", "out.mtl", "out.obj", "out.ply"}));
}

TEST_F(ExportTest, FailedObjKeepsTheExistingFiles) {
  // The MTL cannot be renamed over a folder: the OBJ, already staged, must be left as it was.
  std::ofstream(path("keep.obj")) << "old";
  fs::create_directory(path("keep.mtl"));
  EXPECT_THROW(write_solution(path("keep.obj"), scene_, solution_, {}), InputError);
  EXPECT_EQ(read_text(path("keep.obj")), "old");
  EXPECT_EQ(files(), (std::vector<std::string>{"keep.mtl", "keep.obj"}));
}

TEST_F(ExportTest, NonFiniteColourIsAProgrammingError) {
  for (const char* name : {"keep.ply", "keep.obj", "keep.gltf", "keep.glb"})
    std::ofstream(path(name)) << "old";
  solution_.vertex_radiosity[3].g = std::numeric_limits<float>::quiet_NaN();
  solution_.vertex_radiosity[5].b = std::numeric_limits<float>::infinity();
  for (const char* name : {"keep.ply", "keep.obj", "keep.gltf", "keep.glb"}) {
    EXPECT_THROW(write_solution(path(name), scene_, solution_, {}), std::logic_error) << name;
    EXPECT_EQ(read_text(path(name)), "old");
  }
  EXPECT_EQ(files(), (std::vector<std::string>{"keep.glb", "keep.gltf", "keep.obj", "keep.ply"}));

  // Only the chosen quantity is written, and irradiance is finite.
  ExportSettings settings;
  settings.quantity = Quantity::irradiance;
  EXPECT_NO_THROW(write_solution(path("keep.ply"), scene_, solution_, settings));
}

TEST_F(ExportTest, UnwritableFolderLeavesNothing) {
  if (::geteuid() == 0) GTEST_SKIP() << "permissions do not bind root";
  std::ofstream(path("keep.ply")) << "old";
  fs::permissions(dir_, fs::perms::owner_write, fs::perm_options::remove);
  for (const char* name : {"keep.ply", "new.obj", "new.glb"}) {
    EXPECT_THROW(write_solution(path(name), scene_, solution_, {}), InputError) << name;
  }
  fs::permissions(dir_, fs::perms::owner_write, fs::perm_options::add);
  EXPECT_EQ(read_text(path("keep.ply")), "old");
  EXPECT_EQ(files(), std::vector<std::string>{"keep.ply"});
}

TEST_F(ExportTest, PlyWritesNonManifoldElementsAsTheyAre) {
  // A third element on the edge 0–1, one wound against its neighbour, and a bow tie (two
  // elements meeting at vertex 8 only): a half-edge mesh refuses such elements (Debian's
  // OpenMesh 9.0 aborts on some), a PLY face list takes them as they are.
  RadiosityMesh& mesh = solution_.mesh;
  const auto add_vertex = [&](Vec3 p) {
    mesh.positions.push_back(p);
    mesh.normals.push_back({0, 1, 0});
    mesh.vertex_material.push_back(0);
    solution_.vertex_irradiance.push_back({0.125f, 0.25f, 0.375f});
    solution_.vertex_radiosity.push_back({1.5f, 2.5f, 3.5f});
    return uint32_t(mesh.positions.size() - 1);
  };
  const uint32_t a = add_vertex({0.5f, -1.0f, 0.5f}), tie = add_vertex({3.0f, 0.0f, 0.0f});
  const uint32_t b = add_vertex({4.0f, 0.0f, 1.0f}), c = add_vertex({4.0f, 0.0f, -1.0f});
  const uint32_t d = add_vertex({2.0f, 0.0f, 1.0f}), e = add_vertex({2.0f, 0.0f, -1.0f});
  for (const std::array<uint32_t, 3>& element : std::vector<std::array<uint32_t, 3>>{
           {0, 1, a}, {0, 2, 1}, {tie, b, c}, {tie, e, d}}) {
    mesh.elements.push_back(element);
    mesh.element_material.push_back(0);
    mesh.element_surface.push_back(0);
    mesh.element_normal.push_back({0, 1, 0});
    mesh.element_area.push_back(0.5f);
  }

  write_solution(path("out.ply"), scene_, solution_, {});
  const PlyData ply = read_ply(path("out.ply"));
  const auto colours = expected(Quantity::radiance);
  ASSERT_EQ(ply.vertices.size(), mesh.vertex_count());
  ASSERT_EQ(ply.faces.size(), mesh.element_count());
  for (size_t el = 0; el < mesh.element_count(); ++el)
    EXPECT_EQ(ply.faces[el], (std::vector<int>{int(mesh.elements[el][0]), int(mesh.elements[el][1]),
                                               int(mesh.elements[el][2])}));
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    EXPECT_EQ(ply.value(v, "x"), mesh.positions[v].x);
    EXPECT_EQ(ply.value(v, "radiance_red"), colours[v].r);
    EXPECT_EQ(ply.value(v, "radiance_blue"), colours[v].b);
  }
}

TEST_F(ExportTest, MaterialsLoadBackIntoGiltAsTheSameKind) {
  // One element each for a glossy, a mirror and a dielectric material as well.
  scene_.materials.push_back(rc::scene::Material::make_mirror("mirror", rc::Rgb(0.9f, 0.8f, 0.7f)));
  scene_.materials.push_back(
      rc::scene::Material::make_dielectric("glass", 1.33f, rc::Rgb(0.5f, 0.25f, 0.0f)));
  RadiosityMesh& mesh = solution_.mesh;
  for (uint32_t material = 2; material < 5; ++material) {
    const float z = 2.0f + static_cast<float>(material);
    const uint32_t first = static_cast<uint32_t>(mesh.vertex_count());
    for (const Vec3& p : {Vec3(0, 0, z), Vec3(1, 0, z), Vec3(0, 1, z)}) {
      mesh.positions.push_back(p);
      mesh.normals.push_back({0, 0, 1});
      mesh.vertex_material.push_back(material);
      solution_.vertex_radiosity.push_back(rc::Rgb(0.5f));
      solution_.vertex_irradiance.push_back(rc::Rgb(1.0f));
    }
    mesh.elements.push_back({first, first + 1, first + 2});
    mesh.element_material.push_back(material);
  }

  write_solution(path("out.obj"), scene_, solution_, {});
  const rc::scene::Scene obj = rc::io::load_scene_file(path("out.obj"));
  ASSERT_EQ(obj.materials.size(), scene_.materials.size());
  size_t triangles = 0;
  for (const rc::scene::TriangleMesh& m : obj.meshes) triangles += m.triangle_count();
  EXPECT_EQ(triangles, mesh.element_count());
  for (size_t i = 0; i < obj.materials.size(); ++i) {
    const rc::scene::Material& want = scene_.materials[i];
    const rc::scene::Material& got = obj.materials[i];
    SCOPED_TRACE(want.name);
    EXPECT_EQ(got.kind, want.kind);
    EXPECT_EQ(got.albedo, want.albedo);
    EXPECT_EQ(got.specular, want.specular);
    EXPECT_EQ(got.emission, want.emission);
    EXPECT_EQ(got.exponent, want.exponent);
    if (want.kind == rc::scene::MaterialKind::dielectric) {
      EXPECT_EQ(got.ior, want.ior);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(got.absorption[c], want.absorption[c], 1e-6);
    }
  }

  // glTF keeps only the diffuse reading (metallic 0, roughness 1) and the emission.
  write_solution(path("out.glb"), scene_, solution_, {});
  const rc::scene::Scene glb = rc::io::load_scene_file(path("out.glb"));
  ASSERT_EQ(glb.materials.size(), scene_.materials.size());
  for (size_t i = 0; i < glb.materials.size(); ++i) {
    SCOPED_TRACE(scene_.materials[i].name);
    EXPECT_EQ(glb.materials[i].kind, rc::scene::MaterialKind::diffuse);
    EXPECT_EQ(glb.materials[i].albedo, scene_.materials[i].albedo);
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(glb.materials[i].emission[c], scene_.materials[i].emission[c], 1e-5);
  }
}

}  // namespace
}  // namespace gilt::radiosity

namespace gilt::radiosity {
using namespace mesh;
using namespace solver;
using namespace bake;
namespace {

TEST(ExportSnap, CoincidentElementsFacingTheSameWayAreMerged) {
  // Four elements over five vertex slots: element 1 is element 0 again (other vertices at the
  // same positions, listed from another corner: the same face, the same way up), element 2 is
  // element 0 turned over (the other side of a sheet), element 3 another face.
  RadiosityMesh mesh;
  mesh.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 0),
                    Vec3(1, 1, 0)};
  mesh.normals.assign(mesh.positions.size(), Vec3(0, 0, 1));
  mesh.vertex_material.assign(mesh.positions.size(), 0);
  mesh.elements = {{0, 1, 2}, {3, 4, 5}, {0, 2, 1}, {1, 6, 2}};
  mesh.element_material = {0, 0, 0, 0};
  mesh.element_surface = {0, 1, 2, 3};
  mesh.element_normal = {Vec3(0, 0, 1), Vec3(0, 0, 1), Vec3(0, 0, -1), Vec3(0, 0, 1)};
  mesh.element_area = {0.5f, 0.5f, 0.5f, 0.5f};
  SnapStats stats;
  const RadiosityMesh out = without_coincident(mesh, &stats);
  EXPECT_EQ(stats.coincident_merged, 1u);
  EXPECT_EQ(stats.back_to_back, 1u);
  ASSERT_EQ(out.element_count(), 3u);
  EXPECT_EQ(out.element_surface, (std::vector<uint32_t>{0, 2, 3}));  // the first of the pair stays
  EXPECT_EQ(out.elements[1], (std::array<uint32_t, 3>{0, 2, 1}));
  EXPECT_EQ(out.element_normal.size(), 3u);
  EXPECT_EQ(out.element_area.size(), 3u);
  EXPECT_EQ(out.positions.size(), mesh.positions.size());
}

TEST(ExportSnap, ExportedVerticesLieOnACurvedInput) {
  // A sphere of 1,280 flat facets, remeshed into fewer, larger elements whose vertices lie on
  // it; bisecting elements (as adaptive subdivision does at shadow edges) puts new vertices at
  // the middle of chords, inside the sphere, and the export moves them back onto it.
  rc::scene::Scene scene;
  scene.materials.push_back(rc::scene::Material::make_diffuse("grey", rc::Rgb(0.5f)));
  scene.meshes.push_back(test::icosphere(3));
  scene.punctual_lights.push_back(test::uniform_sky(1.0f));
  scene.commit();
  SolverSettings settings;
  settings.mesh.elements = 300;
  settings.progress = false;
  const Solution solution = solve(scene, settings);
  // How far a point is from the input surface (within 0.1), along a normal-facing search.
  const auto off = [&scene](const Vec3& p, const Vec3& n) {
    const std::optional<rc::scene::Hit> h = scene.nearest_triangle(0, p, 0.1f, n, 0.5f);
    return h ? h->t : 1.0f;
  };
  RadiosityMesh raw = solution.mesh;
  std::vector<uint32_t> all(raw.element_count());
  for (uint32_t e = 0; e < all.size(); ++e) all[e] = e;
  ASSERT_GT(split_longest_edges(raw, all, 0.0f), 0u);
  float raw_worst = 0.0f;
  for (size_t v = 0; v < raw.vertex_count(); ++v) raw_worst = std::max(raw_worst, off(raw.positions[v], raw.normals[v]));
  EXPECT_GT(raw_worst, 1e-4f) << "the remeshed vertices already lie on the input: nothing to test";
  SnapStats stats;
  const RadiosityMesh snapped = snapped_to_input(scene, raw, 0.5f * solution.mesh_report.max_edge, &stats);
  EXPECT_EQ(stats.not_moved, 0u);
  // On the surface within float rounding: a few ulps of coordinates of size 1.
  for (size_t v = 0; v < snapped.vertex_count(); ++v) EXPECT_LE(off(snapped.positions[v], snapped.normals[v]), 1e-6f) << v;
}

// --- The exported elements at random points of the input (check_element_colours) ----------------

/// The mesh write_solution writes for a solution.
RadiosityMesh exported_mesh(const rc::scene::Scene& scene, const Solution& solution) {
  return without_coincident(snapped_to_input(scene, solution.mesh, 0.5f * solution.mesh_report.max_edge));
}

/// The furnace (every face emits 0.5 and reflects 0.5; E = π·0.5 / (1 − 0.5) everywhere inside),
/// solved as tests/unit/test_radiosity.cpp solves it, to within 0.2 % at every vertex.
struct Furnace {
  rc::scene::Scene scene;
  Solution solution;
  RadiosityMesh exported;
};

const Furnace& furnace() {
  static const Furnace f = [] {
    Furnace out{rc::io::furnace_scene(0.5f, 0.5f), {}, {}};
    out.scene.commit();
    SolverSettings settings;
    settings.tolerance = 1e-5;
    settings.mesh.elements = 300;
    settings.progress = false;
    out.solution = solve(out.scene, settings);
    out.exported = exported_mesh(out.scene, out.solution);
    return out;
  }();
  return f;
}

/// Where the brute-force twin of check_element_colours' point query reads: the element and the
/// barycentrics (of its second and third corner) of its point nearest to p.
struct Scanned {
  size_t element;
  rc::Vec2 uv;
};

/// Every element scanned for the nearest within `reach` of p whose geometric normal is within
/// 2.5° of n (the first of equals); nothing where none qualifies.
std::optional<Scanned> scan_elements(const RadiosityMesh& mesh, const Vec3& p, const Vec3& n, float reach) {
  const float facing = std::cos(2.5f * rc::kPi / 180.0f);
  std::optional<Scanned> best;
  float best_distance2 = reach * reach;
  for (size_t e = 0; e < mesh.element_count(); ++e) {
    const Vec3 &a = mesh.positions[mesh.elements[e][0]], &b = mesh.positions[mesh.elements[e][1]],
               &c = mesh.positions[mesh.elements[e][2]];
    const Vec3 normal = glm::cross(b - a, c - a);
    if (!(glm::dot(normal, n) > facing * glm::length(normal))) continue;
    const rc::Vec2 uv = rc::util::closest_point_on_triangle(p, a, b, c);
    const Vec3 x = (1.0f - uv.x - uv.y) * a + uv.x * b + uv.y * c;
    const float d2 = glm::dot(x - p, x - p);
    if (d2 > best_distance2 || (best && d2 == best_distance2)) continue;
    best_distance2 = d2;
    best = Scanned{e, uv};
  }
  return best;
}

/// The unit normal of the input face a checked point was drawn on.
Vec3 face_normal(const rc::scene::Scene& scene, const SurfaceCheckPoint& at) {
  const rc::scene::TriangleMesh& m = scene.meshes[at.mesh];
  const uint32_t* c = &m.indices[3 * size_t(at.triangle)];
  return glm::normalize(
      glm::cross(m.positions[c[1]] - m.positions[c[0]], m.positions[c[2]] - m.positions[c[0]]));
}

TEST(ElementSurfaceCheck, CoversTheFurnaceAndAgreesWithThePathTracerOnAverage) {
  const Furnace& f = furnace();
  CheckSettings settings;
  settings.points = 400;
  settings.samples = 256;
  settings.seed = 7;
  const SurfaceCheckResult r =
      check_element_colours(f.scene, f.exported, f.solution.vertex_irradiance, settings);
  // Six flat faces: the elements cover every point that is compared. Each point is compared on
  // a side drawn at random, and the outside of the closed box takes no light: about half the
  // points are left out as unlit (binomial, σ = 10 of 400), none for another reason.
  EXPECT_EQ(r.unlit + r.points, 400u);
  EXPECT_GT(r.points, 150u);
  EXPECT_LT(r.points, 250u);
  EXPECT_EQ(r.covered, r.points);
  EXPECT_GE(r.covered_share(), 0.99);
  EXPECT_EQ(r.uncovered, 0u);
  ASSERT_EQ(r.compared.size(), r.points);
  // Tolerance of the mean ratio Σ E_baked / Σ E_path. Each point's reference is a mean of
  // independent samples with standard errors se_c per channel; the channels come from the same
  // paths, so the standard error of their sum is at most Σ_c se_c, and the points are
  // independent: σ(Σ E_path) ≤ √(Σ_points (Σ_c se_c)²), and the ratio's relative σ is that over
  // Σ E_path. 4σ (a normal deviate beyond it: 6·10⁻⁵) plus the solve's own error at every vertex
  // in this furnace, 0.2 % (tests/unit/test_radiosity.cpp), taken in full.
  double reference = 0.0, variance = 0.0;
  for (const SurfaceCheckPoint& at : r.compared) {
    reference += double(at.reference.r) + at.reference.g + at.reference.b;
    const double se = double(at.standard_error.r) + at.standard_error.g + at.standard_error.b;
    variance += se * se;
  }
  const double sigma = std::sqrt(variance) / reference;
  std::printf("[ measured ] furnace: %zu points, %zu uncovered, mean ratio %.5f (sigma %.5f), relMSE %.3g "
              "(reference's %.3g)\n",
              r.points, r.uncovered, r.mean_ratio, sigma, r.relative_mse, r.reference_share);
  EXPECT_GT(sigma, 0.0);
  EXPECT_LT(sigma, 0.005) << "too few samples for the ratio to tell anything";
  EXPECT_NEAR(r.mean_ratio, 1.0, 4.0 * sigma + 2e-3);
}

TEST(ElementSurfaceCheck, ReadsTheElementAScanFindsAndCountsHolesExactly) {
  const Furnace& f = furnace();
  const float reach = 1e-4f * glm::length(f.scene.bounds().diagonal());
  // A value that changes over every face, linear in position: the wrong element or the wrong
  // barycentrics would show, and the right ones give the point's own value.
  std::vector<rc::Rgb> field(f.exported.vertex_count());
  for (size_t v = 0; v < field.size(); ++v) {
    const Vec3& p = f.exported.positions[v];
    field[v] = rc::Rgb(2.0f + p.x, 2.0f + p.y, 2.0f + p.z);
  }
  CheckSettings settings;
  settings.points = 300;
  settings.samples = 8;  // the reference's noise does not matter here, nor does it decide which points count
  const SurfaceCheckResult whole = check_element_colours(f.scene, f.exported, field, settings);
  // About half the points are drawn on the outside of the box, where no light is (σ = 8.7 of 300).
  ASSERT_EQ(whole.points + whole.unlit, 300u);
  ASSERT_GT(whole.points, 110u);
  EXPECT_EQ(whole.uncovered, 0u);
  const auto scan = [&](const RadiosityMesh& mesh, const SurfaceCheckPoint& at) {
    return scan_elements(mesh, at.position, face_normal(f.scene, at), reach);
  };
  for (const SurfaceCheckPoint& at : whole.compared) {
    const std::optional<Scanned> found = scan(f.exported, at);
    ASSERT_TRUE(found) << "point " << at.position.x << " " << at.position.y << " " << at.position.z;
    const auto& corner = f.exported.elements[found->element];
    const rc::Rgb scanned = (1.0f - found->uv.x - found->uv.y) * field[corner[0]] +
                            found->uv.x * field[corner[1]] + found->uv.y * field[corner[2]];
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(at.baked[c], scanned[c], 1e-5f);
      EXPECT_NEAR(at.baked[c], 2.0f + at.position[c], 1e-4f);
    }
  }
  const auto uncovered_by_scan = [&](const RadiosityMesh& mesh) {
    size_t n = 0;
    for (const SurfaceCheckPoint& at : whole.compared)
      if (!scan(mesh, at)) ++n;
    return n;
  };

  // The elements under the first ten compared points taken out: exactly the points the scan no
  // longer finds a face for are uncovered (those inside them, but for any within reach of a
  // neighbour), the others compared as before.
  std::vector<char> removed(f.exported.element_count(), 0);
  for (size_t i = 0; i < 10; ++i) removed[scan(f.exported, whole.compared[i])->element] = 1;
  RadiosityMesh holed = f.exported;
  holed.elements.clear();
  for (size_t e = 0; e < f.exported.element_count(); ++e)
    if (!removed[e]) holed.elements.push_back(f.exported.elements[e]);
  const size_t expected = uncovered_by_scan(holed);
  ASSERT_GT(expected, 0u) << "the holes hold no point: nothing to test";
  const SurfaceCheckResult with_hole = check_element_colours(f.scene, holed, field, settings);
  EXPECT_EQ(with_hole.uncovered, expected);
  EXPECT_EQ(with_hole.points, whole.points - expected);
  EXPECT_EQ(with_hole.covered, with_hole.points);
  EXPECT_EQ(with_hole.unlit, whole.unlit);

  // The top face's elements turned over (facing out of the box): every point drawn on it is
  // uncovered, since an element must face the way its input face does.
  RadiosityMesh flipped = f.exported;
  size_t turned = 0;
  for (auto& e : flipped.elements) {
    const Vec3 n = glm::cross(flipped.positions[e[1]] - flipped.positions[e[0]],
                              flipped.positions[e[2]] - flipped.positions[e[0]]);
    if (n.y < -0.99f * glm::length(n)) {
      std::swap(e[1], e[2]);
      ++turned;
    }
  }
  ASSERT_GT(turned, 0u);
  size_t on_top = 0;
  for (const SurfaceCheckPoint& at : whole.compared)
    if (face_normal(f.scene, at).y < -0.99f) ++on_top;
  ASSERT_GT(on_top, 0u);
  EXPECT_EQ(uncovered_by_scan(flipped), on_top);
  std::printf("[ measured ] %zu points compared: %zu in the hole, %zu on the turned face\n", whole.points, expected,
              on_top);
  const SurfaceCheckResult upside_down = check_element_colours(f.scene, flipped, field, settings);
  EXPECT_EQ(upside_down.uncovered, on_top);
  EXPECT_EQ(upside_down.points, whole.points - on_top);
  EXPECT_NEAR(upside_down.covered_share(), double(whole.points - on_top) / double(whole.points), 1e-12);

  // No elements at all: nothing covered, and no figure is NaN.
  RadiosityMesh empty = f.exported;
  empty.elements.clear();
  const SurfaceCheckResult none = check_element_colours(f.scene, empty, field, settings);
  EXPECT_EQ(none.points, 0u);
  EXPECT_EQ(none.uncovered, whole.points);
  EXPECT_EQ(none.covered_share(), 0.0);
  EXPECT_EQ(none.mean_ratio, 0.0);
  EXPECT_EQ(none.relative_mse, 0.0);
  EXPECT_THROW(check_element_colours(f.scene, f.exported, std::vector<rc::Rgb>(3), settings),
               std::logic_error);
}

}  // namespace
}  // namespace gilt::radiosity
