// Static triangle meshes: the BVH build and closest-hit raycasts of detsim beside Bullet 3's
// btBvhTriangleMeshShape (if found), in one run.
//
// Method:
// - Geometry: a heightfield-like mesh of 225 x 225 samples 1 m apart (100,352 triangles), heights
//   3 sin(x/7) cos(z/5) + 0.7 sin((x+z)/3) + 0.2 sin(x z / 40), built in Fixed and handed to
//   Bullet as the same numbers in btScalar. Also detsim's heightfield of the same samples (whose
//   cells split along the other diagonal: the same surface within the bumps' curvature).
// - build: detsim's build_mesh (validation, normals, adjacency and the BVH) vs constructing
//   btBvhTriangleMeshShape (quantized AABB compression on, Bullet's default) over a
//   btTriangleIndexVertexArray. Each iteration builds from scratch.
// - rays: 10^6 rays (--mesh_rays=N), drawn once with detsim::Rng: origins over the mesh 5-25 m
//   above its highest point, unit directions pointing down, 200 m long. detsim: raycast(mesh)
//   (closest hit, ties to the lower index); Bullet: performRaycast with a
//   btTriangleRaycastCallback that keeps the closest hit, and btCollisionWorld::rayTest with
//   ClosestRayResultCallback over one static object (the path a game uses). One iteration is the
//   whole batch; the counter "hits" lets the reader check that the engines agree.
// Bench code is not simulation code: double is used freely here.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <detsim/core/rng.hpp>
#include <detsim/fixed/math.hpp>
#include <detsim/fixed/vec3.hpp>

#include "sim/src/geometry/heightfield.hpp"
#include "sim/src/geometry/mesh.hpp"

#if DETSIM_BENCH_HAVE_BULLET
#include <BulletCollision/NarrowPhaseCollision/btRaycastCallback.h>
#include <btBulletCollisionCommon.h>
#endif

namespace {

using namespace detsim;
using namespace detsim::literals;
using namespace detsim::sim_detail;

constexpr std::uint32_t side = 225;  // samples per side: 2 * 224^2 = 100,352 triangles
std::uint32_t ray_count = 1'000'000;

Fixed fx(std::int32_t n) {
  return Fixed::from_int(n);
}

struct Geometry {
  std::vector<Vec3> vertices;
  std::vector<std::uint32_t> indices;
  HeightfieldDef heightfield;
};

const Geometry& geometry() {
  static const Geometry g = [] {
    Geometry out;
    out.heightfield = {side, side, fx(1), {}};
    for (std::uint32_t i = 0; i < side; ++i) {
      for (std::uint32_t j = 0; j < side; ++j) {
        const Fixed x = fx(static_cast<std::int32_t>(j));
        const Fixed z = fx(static_cast<std::int32_t>(i));
        const Fixed y = fx(3) * sin(x / fx(7)) * cos(z / fx(5)) + 0.7_fx * sin((x + z) / fx(3)) +
                        0.2_fx * sin(x * z / fx(40));
        out.vertices.push_back({x, y, z});
        out.heightfield.heights.push_back(y);
      }
    }
    for (std::uint32_t i = 0; i + 1 < side; ++i) {
      for (std::uint32_t j = 0; j + 1 < side; ++j) {
        const std::uint32_t a = i * side + j;
        const std::uint32_t b = (i + 1) * side + j;
        const std::uint32_t c = b + 1;
        const std::uint32_t d = a + 1;
        out.indices.insert(out.indices.end(), {a, b, d, b, c, d});
      }
    }
    return out;
  }();
  return g;
}

struct Ray {
  Vec3 p;
  Vec3 v;
};
constexpr std::int32_t ray_length = 200;

const std::vector<Ray>& rays() {
  static const std::vector<Ray> r = [] {
    std::vector<Ray> out;
    Rng rng(42);
    const Fixed extent = fx(static_cast<std::int32_t>(side - 1));
    for (std::uint32_t i = 0; i < ray_count; ++i) {
      Ray ray;
      ray.p = {rng.uniform(Fixed::zero(), extent), rng.uniform(fx(10), fx(30)),
               rng.uniform(Fixed::zero(), extent)};
      ray.v = rng.unit_vector();
      if (ray.v.y > Fixed::zero()) ray.v.y = -ray.v.y;
      out.push_back(ray);
    }
    return out;
  }();
  return r;
}

void BM_build_detsim(benchmark::State& state) {
  const Geometry& g = geometry();
  for (auto _ : state) {
    auto mesh = build_mesh(g.vertices, g.indices);
    benchmark::DoNotOptimize(mesh);
  }
  state.counters["triangles"] = static_cast<double>(g.indices.size() / 3);
}

template <class Shape>
void detsim_rays(benchmark::State& state, const Shape& shape) {
  const std::vector<Ray>& batch = rays();
  std::int64_t hits = 0;
  for (auto _ : state) {
    hits = 0;
    for (const Ray& r : batch) {
      const auto hit = raycast(shape, r.p, r.v, fx(ray_length));
      benchmark::DoNotOptimize(hit);
      hits += hit ? 1 : 0;
    }
  }
  state.counters["hits"] = static_cast<double>(hits);
  state.counters["ns_per_ray"] = benchmark::Counter(
      static_cast<double>(batch.size()) * 1e-9,
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_rays_detsim_mesh(benchmark::State& state) {
  const Mesh mesh = build_mesh(geometry().vertices, geometry().indices).value();
  detsim_rays(state, mesh);
}

void BM_rays_detsim_heightfield(benchmark::State& state) {
  const Heightfield hf = build_heightfield(geometry().heightfield).value();
  detsim_rays(state, hf);
}

#if DETSIM_BENCH_HAVE_BULLET

struct BulletMesh {
  std::vector<btScalar> vertices;
  std::vector<int> indices;
  std::unique_ptr<btTriangleIndexVertexArray> array;

  BulletMesh() {
    const Geometry& g = geometry();
    for (const Vec3& v : g.vertices) {
      vertices.push_back(static_cast<btScalar>(v.x.to_double()));
      vertices.push_back(static_cast<btScalar>(v.y.to_double()));
      vertices.push_back(static_cast<btScalar>(v.z.to_double()));
    }
    for (const std::uint32_t i : g.indices)
      indices.push_back(static_cast<int>(i));
    array = std::make_unique<btTriangleIndexVertexArray>(
        static_cast<int>(indices.size() / 3), indices.data(), 3 * static_cast<int>(sizeof(int)),
        static_cast<int>(vertices.size() / 3), vertices.data(),
        3 * static_cast<int>(sizeof(btScalar)));
  }
};

btVector3 to_bt(Vec3 v) {
  return {static_cast<btScalar>(v.x.to_double()), static_cast<btScalar>(v.y.to_double()),
          static_cast<btScalar>(v.z.to_double())};
}

void BM_build_bullet(benchmark::State& state) {
  BulletMesh mesh;
  for (auto _ : state) {
    auto shape = std::make_unique<btBvhTriangleMeshShape>(mesh.array.get(), true, true);
    benchmark::DoNotOptimize(shape.get());
  }
}

/// The closest hit: each reported hit lowers the fraction that later triangles must beat.
struct ClosestTriangle : btTriangleRaycastCallback {
  ClosestTriangle(const btVector3& from, const btVector3& to)
      : btTriangleRaycastCallback(from, to) {}
  btScalar reportHit(const btVector3&, btScalar fraction, int, int) override {
    hit = true;
    return fraction;
  }
  bool hit = false;
};

void BM_rays_bullet_shape(benchmark::State& state) {
  BulletMesh mesh;
  btBvhTriangleMeshShape shape(mesh.array.get(), true, true);
  std::vector<std::pair<btVector3, btVector3>> batch;
  for (const Ray& r : rays())
    batch.emplace_back(to_bt(r.p), to_bt(r.p + r.v * fx(ray_length)));
  std::int64_t hits = 0;
  for (auto _ : state) {
    hits = 0;
    for (const auto& [from, to] : batch) {
      ClosestTriangle callback(from, to);
      shape.performRaycast(&callback, from, to);
      hits += callback.hit ? 1 : 0;
    }
  }
  state.counters["hits"] = static_cast<double>(hits);
  state.counters["ns_per_ray"] = benchmark::Counter(
      static_cast<double>(batch.size()) * 1e-9,
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_rays_bullet_world(benchmark::State& state) {
  BulletMesh mesh;
  btBvhTriangleMeshShape shape(mesh.array.get(), true, true);
  btDefaultCollisionConfiguration config;
  btCollisionDispatcher dispatcher(&config);
  btDbvtBroadphase broadphase;
  btCollisionWorld world(&dispatcher, &broadphase, &config);
  btCollisionObject object;
  object.setCollisionShape(&shape);
  world.addCollisionObject(&object);
  world.updateAabbs();
  std::vector<std::pair<btVector3, btVector3>> batch;
  for (const Ray& r : rays())
    batch.emplace_back(to_bt(r.p), to_bt(r.p + r.v * fx(ray_length)));
  std::int64_t hits = 0;
  for (auto _ : state) {
    hits = 0;
    for (const auto& [from, to] : batch) {
      btCollisionWorld::ClosestRayResultCallback callback(from, to);
      world.rayTest(from, to, callback);
      hits += callback.hasHit() ? 1 : 0;
    }
  }
  world.removeCollisionObject(&object);
  state.counters["hits"] = static_cast<double>(hits);
  state.counters["ns_per_ray"] = benchmark::Counter(
      static_cast<double>(batch.size()) * 1e-9,
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

#endif

bool parse_options(int& argc, char** argv) {
  constexpr std::string_view flag = "--mesh_rays=";
  int kept = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg(argv[i]);
    if (arg.substr(0, flag.size()) == flag) {
      const std::string text(arg.substr(flag.size()));
      char* end = nullptr;
      const unsigned long v = std::strtoul(text.c_str(), &end, 10);
      if (text.empty() || *end != '\0' || v == 0 || v > 100'000'000) {
        std::fprintf(stderr, "mesh_bench: %s needs a whole number from 1 to 10^8\n", argv[i]);
        return false;
      }
      ray_count = static_cast<std::uint32_t>(v);
      continue;
    }
    argv[kept++] = argv[i];
  }
  argc = kept;
  return true;
}

}  // namespace

BENCHMARK(BM_build_detsim)->Unit(benchmark::kMillisecond);
#if DETSIM_BENCH_HAVE_BULLET
BENCHMARK(BM_build_bullet)->Unit(benchmark::kMillisecond);
#endif
BENCHMARK(BM_rays_detsim_mesh)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_rays_detsim_heightfield)->Unit(benchmark::kMillisecond)->Iterations(1);
#if DETSIM_BENCH_HAVE_BULLET
BENCHMARK(BM_rays_bullet_shape)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_rays_bullet_world)->Unit(benchmark::kMillisecond)->Iterations(1);
#endif

int main(int argc, char** argv) {
  if (!parse_options(argc, argv)) return 2;
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
