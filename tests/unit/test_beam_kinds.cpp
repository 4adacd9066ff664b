// The beam kind modules (protocol/beams/): the parser dispatches on their
// kType and allowed keys, hello lists them, and each kind's GPU record, rig
// bounds and reference regions.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "protocol/scene_json.hpp"

namespace beamcast {
namespace {

using nlohmann::json;

ErrorInfo error_of(const json& beam) {
  json scene = {{"beams", json::array({beam})}, {"cameras", json::array({json::object()})}};
  try {
    parse_scene(scene, {});
  } catch (const ProtocolError& e) {
    return e.info();
  }
  ADD_FAILURE() << "accepted: " << beam.dump();
  return {};
}

TEST(BeamKinds, CapabilitiesListEveryKindOfTheVariant) {
  const json caps = scene_capabilities();
  std::vector<std::string> listed = caps.at("beam_types");
  EXPECT_EQ(listed, (std::vector<std::string>{"sphere", "capsule"}));
  std::vector<std::string> types;
  for (std::string_view t : beam_types()) types.emplace_back(t);
  EXPECT_EQ(listed, types);
}

TEST(BeamKinds, UnknownTypeListsTheKinds) {
  const ErrorInfo e = error_of({{"type", "cone"}, {"radius", 1}});
  EXPECT_EQ(e.code, "invalid_value");
  EXPECT_EQ(e.path, "/beams/0/type");
  EXPECT_NE(e.message.find(R"("sphere", "capsule")"), std::string::npos) << e.message;
  EXPECT_NE(e.message.find("cone"), std::string::npos) << e.message;
}

TEST(BeamKinds, AnotherKindsKeyIsRefusedBeforeMissingFields) {
  // A sphere given a capsule's axis and no radius: the typo-like key is the
  // error reported (keys are checked before any field is read).
  const ErrorInfo e = error_of({{"type", "sphere"}, {"p0", {0, 0, 0}}});
  EXPECT_EQ(e.code, "unknown_field");
  EXPECT_EQ(e.path, "/beams/0/p0");
  EXPECT_NE(e.message.find("center"), std::string::npos) << e.message;
}

TEST(BeamKinds, KindFieldsAreReadAfterTheSharedOnes) {
  const ErrorInfo missing_radius = error_of({{"type", "sphere"}});
  EXPECT_EQ(missing_radius.code, "missing_field");
  EXPECT_EQ(missing_radius.path, "/beams/0/radius");
  const ErrorInfo missing_center = error_of({{"type", "sphere"}, {"radius", 1}});
  EXPECT_EQ(missing_center.code, "missing_field");
  EXPECT_EQ(missing_center.path, "/beams/0/center");
  // The capsule's degenerate-axis rule sees the beam's radius.
  const ErrorInfo degenerate =
      error_of({{"type", "capsule"}, {"p0", {0, 0, 0}}, {"p1", {0, 0, 1e-7}}, {"radius", 1000}});
  EXPECT_EQ(degenerate.code, "degenerate_capsule");
  EXPECT_EQ(degenerate.path, "/beams/0/p1");
}

TEST(BeamKinds, GpuRecordIsCameraRelative) {
  const Vec3 eye{1, 2, 3};
  const BeamGpu s = SphereBeam{{4, 6, 8}}.gpu(eye);
  EXPECT_EQ(s.p0, (Vec3{3, 4, 5}));
  EXPECT_EQ(s.length, 0.0);
  EXPECT_EQ(s.caps_kind, (Vec3{0, 0, 0}));  // kind 0: sphere
  const BeamGpu c = CapsuleBeam{{1, 2, 3}, {1, 2, 7}, true, false}.gpu(eye);
  EXPECT_EQ(c.p0, (Vec3{0, 0, 0}));
  EXPECT_EQ(c.axis, (Vec3{0, 0, 1}));
  EXPECT_EQ(c.length, 4.0);
  EXPECT_EQ(c.caps_kind, (Vec3{1, 0, 1}));  // cap0 only, kind 1: capsule
}

TEST(BeamKinds, DefiningBoundsAreCentreOrAxisEnds) {
  const Aabb s = SphereBeam{{1, 2, 3}}.defining_bounds();
  EXPECT_EQ(s.lo, (Vec3{1, 2, 3}));
  EXPECT_EQ(s.hi, (Vec3{1, 2, 3}));
  const Aabb c = CapsuleBeam{{1, 5, 3}, {-1, 2, 4}}.defining_bounds();
  EXPECT_EQ(c.lo, (Vec3{-1, 2, 3}));
  EXPECT_EQ(c.hi, (Vec3{1, 5, 4}));
}

// Records the regions a kind asks the reference to integrate.
class Recorder final : public RadialIntegrals {
 public:
  struct Call {
    bool line;
    Vec3 a;
    double lo, hi;
  };
  mutable std::vector<Call> calls;
  double point(const Vec3& a, double lo, double hi) const override {
    calls.push_back({false, a, lo, hi});
    return 1.0;
  }
  double line(const Vec3& a, const Vec3& /*w*/, double lo, double hi) const override {
    calls.push_back({true, a, lo, hi});
    return 10.0;
  }
};

TEST(BeamKinds, CapsuleSplitsARayAlongItsAxisIntoCapSlabCap) {
  // Capsule of length 4, radius 1, along z; in the reference's units (about
  // the centre, per radius) its ends are at z = -2 and z = 2. A ray along +z
  // through the axis: cap0 before sigma = -2 - q_z, slab, cap1 after.
  const CapsuleBeam cap{{0, 0, -2}, {0, 0, 2}};
  const ReferenceFrame frame = cap.reference_frame(1.0);
  EXPECT_EQ(frame.c, (Vec3{0, 0, 0}));
  EXPECT_EQ(frame.bound2, 9.0);  // (L / 2r + 1)^2
  Recorder rec;
  const double e = cap.reference_energy(rec, {0, 0, 0}, {0, 0, 1}, -3.0, 3.0, 1.0);
  EXPECT_EQ(e, 12.0);  // one slab piece and two cap pieces
  ASSERT_EQ(rec.calls.size(), 3u);
  EXPECT_TRUE(rec.calls[0].line);
  EXPECT_EQ(rec.calls[0].lo, -2.0);
  EXPECT_EQ(rec.calls[0].hi, 2.0);
  EXPECT_FALSE(rec.calls[1].line);
  EXPECT_EQ(rec.calls[1].a, (Vec3{0, 0, -2}));
  EXPECT_EQ(rec.calls[1].lo, -3.0);
  EXPECT_EQ(rec.calls[1].hi, -2.0);
  EXPECT_EQ(rec.calls[2].a, (Vec3{0, 0, 2}));
  EXPECT_EQ(rec.calls[2].lo, 2.0);
  EXPECT_EQ(rec.calls[2].hi, 3.0);
  // Without caps only the slab is integrated.
  Recorder flat;
  CapsuleBeam{{0, 0, -2}, {0, 0, 2}, false, false}.reference_energy(flat, {0, 0, 0}, {0, 0, 1},
                                                                    -3.0, 3.0, 1.0);
  EXPECT_EQ(flat.calls.size(), 1u);
}

TEST(BeamKinds, SphereIsOnePointRegionAboutItsCentre) {
  const SphereBeam s{{5, 0, 0}};
  EXPECT_EQ(s.reference_frame(2.0).c, (Vec3{5, 0, 0}));
  EXPECT_EQ(s.reference_frame(2.0).bound2, 1.0);
  Recorder rec;
  EXPECT_EQ(s.reference_energy(rec, {0.5, 0, 0}, {0, 1, 0}, -0.8, 0.8, 2.0), 1.0);
  ASSERT_EQ(rec.calls.size(), 1u);
  EXPECT_EQ(rec.calls[0].a, (Vec3{0, 0, 0}));
  EXPECT_EQ(rec.calls[0].lo, -0.8);
}

}  // namespace
}  // namespace beamcast
