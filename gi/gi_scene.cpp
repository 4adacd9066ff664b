#include "gi/gi_scene.hpp"

#include <embree3/rtcore.h>

#include "protocol/check.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

namespace beamcast {
namespace {

struct Triangle {
  Vec3 a, b, c;
  bool one_sided;
};

class CollectTriangles final : public TriangleSink {
 public:
  void add(const Vec3& a, const Vec3& b, const Vec3& c, bool one_sided) override {
    tris.push_back({a, b, c, one_sided});
  }
  std::vector<Triangle> tris;
};

// What an Embree geometry stands for.
struct Element {
  int occluder = -1;
  int light = -1;
  std::vector<Triangle> tris;  // triangle kinds; empty for user geometry
};

// The double-precision ray travels with Embree's context, and the user
// geometry's exact hit comes back through it.
struct Context {
  RTCIntersectContext rtc;
  Vec3 o, v;
  double t_min, t_max;
  const Scene* scene;
  double user_t = 0.0;
  Vec3 user_n{};
};

// Bounds of unbounded elements (planes): Embree drops primitives whose
// bounds reach past its FLT_LARGE (1.844e18) as invalid.
constexpr float kHuge = 1e17f;

float clamp_bound(double x) {
  return static_cast<float>(std::clamp(x, -static_cast<double>(kHuge), static_cast<double>(kHuge)));
}

// The exact hit of a user-geometry element (an analytic occluder or a quad
// light) on the context's double ray, within (lo, hi].
std::optional<OccluderHit> user_hit(const Element& e, const Context& c, double lo, double hi) {
  if (e.occluder >= 0) {
    return std::visit(
        [&](const auto& kind) -> std::optional<OccluderHit> {
          using Kind = std::decay_t<decltype(kind)>;
          if constexpr (Kind::kGpu != GpuForm::kTriangles) {  // analytic kinds, SLIM
            auto h = kind.intersect(c.o, c.v, lo, hi);
            if (h && h->t <= lo) h.reset();
            return h;
          } else {
            return std::nullopt;
          }
        },
        c.scene->occluders[static_cast<std::size_t>(e.occluder)].shape);
  }
  // A seen light (an element only if it has an outline), with its outline's normal.
  return std::visit(
      [&](const auto& kind) -> std::optional<OccluderHit> {
        const std::optional<LightOutline> outline = kind.outline();
        if (!outline) return std::nullopt;
        const auto t = kind.hit(c.o, c.v, hi);
        if (!t || *t <= lo) return std::nullopt;
        return OccluderHit{*t, outline->normal};
      },
      c.scene->lights[static_cast<std::size_t>(e.light)].shape);
}

void user_bounds(const RTCBoundsFunctionArguments* args) {
  const auto* b = static_cast<const Aabb*>(args->geometryUserPtr);
  args->bounds_o->lower_x = clamp_bound(b->lo[0]);
  args->bounds_o->lower_y = clamp_bound(b->lo[1]);
  args->bounds_o->lower_z = clamp_bound(b->lo[2]);
  args->bounds_o->upper_x = clamp_bound(b->hi[0]);
  args->bounds_o->upper_y = clamp_bound(b->hi[1]);
  args->bounds_o->upper_z = clamp_bound(b->hi[2]);
}

struct UserData {
  Aabb bounds;
  const Element* element;
};

void user_intersect(const RTCIntersectFunctionNArguments* args) {
  if (args->N != 1 || !args->valid[0]) return;
  auto* c = reinterpret_cast<Context*>(args->context);
  const auto* u = static_cast<const UserData*>(args->geometryUserPtr);
  auto* rh = reinterpret_cast<RTCRayHit*>(args->rayhit);
  const auto h = user_hit(*u->element, *c, c->t_min, std::min(c->t_max, static_cast<double>(rh->ray.tfar)));
  if (!h) return;
  rh->ray.tfar = static_cast<float>(h->t);
  rh->hit.geomID = args->geomID;
  rh->hit.primID = args->primID;
  rh->hit.Ng_x = static_cast<float>(h->n[0]);
  rh->hit.Ng_y = static_cast<float>(h->n[1]);
  rh->hit.Ng_z = static_cast<float>(h->n[2]);
  c->user_t = h->t;
  c->user_n = h->n;
}

void user_occluded(const RTCOccludedFunctionNArguments* args) {
  if (args->N != 1 || !args->valid[0]) return;
  auto* c = reinterpret_cast<Context*>(args->context);
  const auto* u = static_cast<const UserData*>(args->geometryUserPtr);
  auto* ray = reinterpret_cast<RTCRay*>(args->ray);
  if (user_hit(*u->element, *c, c->t_min, c->t_max)) ray->tfar = -std::numeric_limits<float>::infinity();
}

// What Embree's Ray::valid() asserts: origin and direction within
// FLT_LARGE (1.844e18) and not NaN, tnear and tfar not NaN.
bool embree_ray_valid(const RTCRay& r) {
  constexpr float kLarge = 1.844e18f;
  for (const float x : {r.org_x, r.org_y, r.org_z, r.dir_x, r.dir_y, r.dir_z}) {
    if (!(std::abs(x) <= kLarge)) return false;
  }
  return !std::isnan(r.tnear) && !std::isnan(r.tfar);
}

}  // namespace

struct GiScene::Impl {
  RTCDevice device = nullptr;
  RTCScene rtc = nullptr;
  std::vector<Element> elements;  // by geomID
  std::vector<UserData> user;     // stable (reserved) storage for user geometry data

  ~Impl() {
    if (rtc) rtcReleaseScene(rtc);
    if (device) rtcReleaseDevice(device);
  }
};

GiScene::GiScene(const Scene& scene) : impl_(std::make_unique<Impl>()), scene_(&scene) {
  Impl& m = *impl_;
  m.device = rtcNewDevice(nullptr);
  if (!m.device) throw std::runtime_error("Embree: rtcNewDevice failed");
  m.rtc = rtcNewScene(m.device);
  rtcSetSceneFlags(m.rtc, RTC_SCENE_FLAG_ROBUST);
  m.elements.reserve(scene.occluders.size() + scene.lights.size());
  m.user.reserve(scene.occluders.size() + scene.lights.size());
  Aabb extent;

  auto add_user = [&](Element e, const Aabb& bounds) {
    m.elements.push_back(std::move(e));
    m.user.push_back({bounds, &m.elements.back()});
    RTCGeometry g = rtcNewGeometry(m.device, RTC_GEOMETRY_TYPE_USER);
    rtcSetGeometryUserPrimitiveCount(g, 1);
    rtcSetGeometryUserData(g, &m.user.back());
    rtcSetGeometryBoundsFunction(g, user_bounds, nullptr);
    rtcSetGeometryIntersectFunction(g, user_intersect);
    rtcSetGeometryOccludedFunction(g, user_occluded);
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(m.rtc, g, static_cast<unsigned>(m.elements.size() - 1));
    rtcReleaseGeometry(g);
  };

  for (std::size_t i = 0; i < scene.occluders.size(); ++i) {
    std::visit(
        [&](const auto& kind) {
          using Kind = std::decay_t<decltype(kind)>;
          const Aabb b = kind.bounds();
          if (std::isfinite(b.lo[0]) && std::isfinite(b.hi[0])) extent.grow(b);
          Element e;
          e.occluder = static_cast<int>(i);
          if constexpr (Kind::kGpu == GpuForm::kTriangles) {
            CollectTriangles sink;
            kind.gpu_triangles(sink);
            e.tris = std::move(sink.tris);
            m.elements.push_back(std::move(e));
            const std::vector<Triangle>& tris = m.elements.back().tris;
            RTCGeometry g = rtcNewGeometry(m.device, RTC_GEOMETRY_TYPE_TRIANGLE);
            auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(
                g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * tris.size()));
            auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
                g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), tris.size()));
            for (std::size_t t = 0; t < tris.size(); ++t) {
              const Vec3* corners[3] = {&tris[t].a, &tris[t].b, &tris[t].c};
              for (int k = 0; k < 3; ++k) {
                for (int d = 0; d < 3; ++d) vb[9 * t + 3 * k + d] = static_cast<float>((*corners[k])[d]);
                ib[3 * t + k] = static_cast<unsigned>(3 * t + k);
              }
            }
            rtcCommitGeometry(g);
            rtcAttachGeometryByID(m.rtc, g, static_cast<unsigned>(m.elements.size() - 1));
            rtcReleaseGeometry(g);
          } else {
            add_user(std::move(e), b);
          }
        },
        scene.occluders[i].shape);
  }
  for (std::size_t i = 0; i < scene.lights.size(); ++i) {
    std::visit(
        [&](const auto& kind) {
          const Aabb b = kind.bounds();
          extent.grow(b);
          if (kind.outline()) {  // seen: rays that meet it end there
            Element e;
            e.light = static_cast<int>(i);
            add_user(std::move(e), b);
          }
        },
        scene.lights[i].shape);
  }
  rtcCommitScene(m.rtc);
  if (!extent.empty()) {
    const Vec3 d = extent.hi - extent.lo;
    epsilon_ = 1e-6 * std::max({d[0], d[1], d[2], 1.0});
  }
}

GiScene::~GiScene() = default;

std::optional<SurfaceHit> GiScene::intersect(const Vec3& o, const Vec3& v, double t_min,
                                             double t_max) const {
  Context c;
  rtcInitIntersectContext(&c.rtc);
  c.o = o;
  c.v = v;
  c.scene = scene_;
  c.t_max = t_max;
  // Back faces of one-sided triangles are passed by casting again beyond them.
  for (int pass = 0; pass < 64; ++pass) {
    c.t_min = t_min;
    RTCRayHit rh{};
    rh.ray.org_x = static_cast<float>(o[0]);
    rh.ray.org_y = static_cast<float>(o[1]);
    rh.ray.org_z = static_cast<float>(o[2]);
    rh.ray.dir_x = static_cast<float>(v[0]);
    rh.ray.dir_y = static_cast<float>(v[1]);
    rh.ray.dir_z = static_cast<float>(v[2]);
    rh.ray.tnear = static_cast<float>(t_min);
    rh.ray.tfar = static_cast<float>(std::min(t_max, 1e30));
    rh.ray.mask = 0xFFFFFFFFu;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    // Embree asserts (aborts) on a ray it deems invalid: a NaN, or a
    // coordinate past FLT_LARGE. Parsing keeps every client number away from
    // that (issue 43), so one here is a bug: an internal error for this
    // request, not the end of the server.
    BEAMCAST_CHECK(embree_ray_valid(rh.ray), "a finite ray within Embree's range");
    rtcIntersect1(impl_->rtc, &c.rtc, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
    const Element& e = impl_->elements[rh.hit.geomID];
    SurfaceHit h;
    h.occluder = e.occluder;
    h.light = e.light;
    Vec3 n;
    if (!e.tris.empty()) {
      const Triangle& tri = e.tris[rh.hit.primID];
      n = normalize(cross(tri.b - tri.a, tri.c - tri.a));
      if (!std::isfinite(n[0] + n[1] + n[2])) {  // degenerate in double: Embree's float normal
        n = normalize(Vec3{rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z});
      }
      const double denom = dot(v, n);
      h.t = denom != 0.0 ? dot(tri.a - o, n) / denom : static_cast<double>(rh.ray.tfar);
      if (!(h.t > t_min)) h.t = static_cast<double>(rh.ray.tfar);  // grazing: keep Embree's
      if (tri.one_sided && denom > 0.0) {
        // Past the back face in float, as Embree compares.
        t_min = std::max(static_cast<double>(std::nextafter(rh.ray.tfar, kHuge)), h.t);
        continue;
      }
    } else {
      h.t = c.user_t;
      n = c.user_n;
    }
    h.p = o + h.t * v;
    h.entering = dot(v, n) <= 0.0;
    h.n = h.entering ? n : -1.0 * n;
    return h;
  }
  return std::nullopt;
}

bool GiScene::occluded(const Vec3& o, const Vec3& v, double t_min, double t_max) const {
  // Through intersect: one-sided walls let shadow rays through their backs too.
  const auto h = intersect(o, v, t_min, t_max);
  return h && h->t < t_max;
}

}  // namespace beamcast
