#include "render/volume_pass.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

#include "render/passes.hpp"
#include "render/scene_resources.hpp"
#include "render/gl_validate.hpp"

namespace beamcast {

std::vector<float> transfer_texels(const Volume& volume) {
  std::vector<float> texels(4 * kTransferTexels);
  for (int i = 0; i < kTransferTexels; ++i) {
    const double v = static_cast<double>(i) / (kTransferTexels - 1);
    const Color c = volume.transfer.color(v);
    for (int k = 0; k < 3; ++k) texels[4 * i + k] = static_cast<float>(c[k] * volume.intensity);
    // log2(1 - opacity): the shader's 1 - alpha = exp2(this x ds / unit),
    // one exp2 a sample instead of a pow; an opaque point is held at 2^-64
    // (so neighbouring texels interpolate finite values).
    texels[4 * i + 3] =
        static_cast<float>(std::max(std::log2(1.0 - volume.transfer.opacity(v)), -64.0));
  }
  return texels;
}

std::vector<float> preintegration_texels(const Volume& volume, double step) {
  constexpr int kN = kPreintegrationTexels;
  constexpr int kSub = 16;  // trapezoid points a table cell
  constexpr int kFine = (kN - 1) * kSub;
  const TransferFunction& tf = volume.transfer;
  // lambda(v) = -log2(1 - opacity) / unit (an opaque point held at 2^-64,
  // as the point sampler's table), and the running integrals of lambda and
  // of c sigma = c lambda ln 2 over [0, v] at the fine points.
  std::vector<double> lam_int(kFine + 1), col_int(3 * static_cast<std::size_t>(kFine + 1));
  double prev_lam = 0.0;
  Color prev_col{0.0, 0.0, 0.0};
  for (int f = 0; f <= kFine; ++f) {
    const double v = static_cast<double>(f) / kFine;
    const double lam = -std::max(std::log2(1.0 - tf.opacity(v)), -64.0) / tf.opacity_unit;
    const Color c = tf.color(v);
    Color cs{};
    for (int k = 0; k < 3; ++k) cs[k] = c[k] * lam * std::numbers::ln2;
    if (f == 0) {
      lam_int[0] = 0.0;
      for (int k = 0; k < 3; ++k) col_int[k] = 0.0;
    } else {
      const double h = 1.0 / kFine;
      lam_int[f] = lam_int[f - 1] + 0.5 * h * (lam + prev_lam);
      for (int k = 0; k < 3; ++k) {
        col_int[3 * static_cast<std::size_t>(f) + k] =
            col_int[3 * static_cast<std::size_t>(f - 1) + k] + 0.5 * h * (cs[k] + prev_col[k]);
      }
    }
    prev_lam = lam;
    prev_col = cs;
  }
  std::vector<float> texels(4 * static_cast<std::size_t>(kN) * kN);
  for (int j = 0; j < kN; ++j) {    // back value
    for (int i = 0; i < kN; ++i) {  // front value
      double lam = 0.0;
      Color cs{};
      if (i == j) {
        const double v = static_cast<double>(i) / (kN - 1);
        lam = -std::max(std::log2(1.0 - tf.opacity(v)), -64.0) / tf.opacity_unit;
        const Color c = tf.color(v);
        for (int k = 0; k < 3; ++k) cs[k] = c[k] * lam * std::numbers::ln2;
      } else {
        const std::size_t a = static_cast<std::size_t>(i) * kSub;
        const std::size_t b = static_cast<std::size_t>(j) * kSub;
        const double dv = static_cast<double>(j - i) / (kN - 1);
        lam = (lam_int[b] - lam_int[a]) / dv;
        for (int k = 0; k < 3; ++k) cs[k] = (col_int[3 * b + k] - col_int[3 * a + k]) / dv;
      }
      const double log2_t = -lam * step;
      const double alpha = 1.0 - std::exp2(log2_t);
      const double tau = lam * step * std::numbers::ln2;
      const double scale = tau > 1e-12 ? alpha / tau : 1.0;
      float* t = &texels[4 * (static_cast<std::size_t>(j) * kN + i)];
      for (int k = 0; k < 3; ++k) {
        t[k] = static_cast<float>(cs[k] * step * scale * volume.intensity);
      }
      t[3] = static_cast<float>(log2_t);
    }
  }
  return texels;
}

std::vector<std::uint8_t> brick_occupancy(const VolumeGrid& grid, const std::vector<float>& texels,
                                          std::array<int, 3>* brick_dims) {
  std::array<int, 3>& bd = *brick_dims;
  for (int a = 0; a < 3; ++a) bd[a] = (grid.dims[a] - 1 + kBrickCells - 1) / kBrickCells;
  // Any non-zero opacity among the table texels a value range can reach
  // (a direct scan: the table is small).
  auto any_opacity = [&](double lo, double hi) {
    // A pre-integrated step between values in [lo, hi] blends the table's
    // entries for floor(lo (P - 1)) .. ceil(hi (P - 1)): the range widened
    // to them (so one occupancy serves both integrations).
    constexpr double kP = kPreintegrationTexels - 1;
    lo = std::floor(lo * kP) / kP;
    hi = std::ceil(hi * kP) / kP;
    // The shader reads texel coordinate v (K - 1) + 0.5: values in [lo, hi]
    // blend texels floor(lo (K - 1)) .. ceil(hi (K - 1)).
    const int a = std::clamp(static_cast<int>(std::floor(lo * (kTransferTexels - 1))), 0,
                             kTransferTexels - 1);
    const int b =
        std::clamp(static_cast<int>(std::ceil(hi * (kTransferTexels - 1))), 0, kTransferTexels - 1);
    for (int i = a; i <= b; ++i) {
      if (texels[4 * static_cast<std::size_t>(i) + 3] < 0.0f) return true;  // log2(1 - opacity)
    }
    return false;
  };
  std::vector<std::uint8_t> occupied(static_cast<std::size_t>(bd[0]) * bd[1] * bd[2], 0);
  for (int bz = 0; bz < bd[2]; ++bz) {
    for (int by = 0; by < bd[1]; ++by) {
      for (int bx = 0; bx < bd[0]; ++bx) {
        std::uint16_t lo = 65535, hi = 0;
        const int x1 = std::min(kBrickCells * (bx + 1), grid.dims[0] - 1);
        const int y1 = std::min(kBrickCells * (by + 1), grid.dims[1] - 1);
        const int z1 = std::min(kBrickCells * (bz + 1), grid.dims[2] - 1);
        for (int z = kBrickCells * bz; z <= z1; ++z) {
          for (int y = kBrickCells * by; y <= y1; ++y) {
            const std::size_t row = (static_cast<std::size_t>(z) * grid.dims[1] + y) * grid.dims[0];
            for (int x = kBrickCells * bx; x <= x1; ++x) {
              lo = std::min(lo, grid.values[row + x]);
              hi = std::max(hi, grid.values[row + x]);
            }
          }
        }
        occupied[(static_cast<std::size_t>(bz) * bd[1] + by) * bd[0] + bx] =
            any_opacity(lo / 65535.0, hi / 65535.0) ? 1 : 0;
      }
    }
  }
  return occupied;
}

namespace {

std::shared_ptr<const VolumeTextures> upload_volume(const Volume& vol, const VolumeSettings& s,
                                                    const std::vector<float>& tf) {
  auto u = std::make_shared<VolumeTextures>();
  std::shared_ptr<const VolumeGrid> grid = vol.grid;
  if (s.level > 0) grid = volume_level(*vol.grid, s.level, s.pyramid);
  u->dims = grid->dims;
  GLuint tex = 0;
  glCreateTextures(GL_TEXTURE_3D, 1, &tex);
  u->values = GlTexture(tex);
  glTextureStorage3D(tex, 1, GL_R16, u->dims[0], u->dims[1], u->dims[2]);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 2);
  glTextureSubImage3D(tex, 0, 0, 0, 0, u->dims[0], u->dims[1], u->dims[2], GL_RED,
                      GL_UNSIGNED_SHORT, grid->values.data());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTextureParameteri(tex, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(tex, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  for (GLenum wrap : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R}) {
    glTextureParameteri(tex, wrap, GL_CLAMP_TO_EDGE);
  }
  glCreateTextures(GL_TEXTURE_1D, 1, &tex);
  u->transfer = GlTexture(tex);
  glTextureStorage1D(tex, 1, GL_RGBA32F, kTransferTexels);
  glTextureSubImage1D(tex, 0, 0, kTransferTexels, GL_RGBA, GL_FLOAT, tf.data());
  glTextureParameteri(tex, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(tex, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(tex, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  const std::vector<std::uint8_t> bricks = brick_occupancy(*grid, tf, &u->brick_dims);
  u->any_empty = std::find(bricks.begin(), bricks.end(), 0) != bricks.end();
  glCreateTextures(GL_TEXTURE_3D, 1, &tex);
  u->bricks = GlTexture(tex);
  glTextureStorage3D(tex, 1, GL_R8UI, u->brick_dims[0], u->brick_dims[1], u->brick_dims[2]);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTextureSubImage3D(tex, 0, 0, 0, 0, u->brick_dims[0], u->brick_dims[1], u->brick_dims[2],
                      GL_RED_INTEGER, GL_UNSIGNED_BYTE, bricks.data());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  // An integer texture with a linear filter (the default magnification
  // filter) is incomplete and reads as 0 everywhere: nearest.
  glTextureParameteri(tex, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTextureParameteri(tex, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  gl_check("volume upload");
  return u;
}

std::shared_ptr<const GlTexture> upload_preintegration(const Volume& volume, double step) {
  const std::vector<float> texels = preintegration_texels(volume, step);
  auto t = std::make_shared<GlTexture>(
      make_texture_2d(GL_RGBA32F, kPreintegrationTexels, kPreintegrationTexels));
  glTextureSubImage2D(t->get(), 0, 0, 0, kPreintegrationTexels, kPreintegrationTexels, GL_RGBA,
                      GL_FLOAT, texels.data());
  // Linear between entries: a step's (front, back) falls between them.
  glTextureParameteri(t->get(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(t->get(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  gl_check("pre-integration table upload");
  return t;
}

// The world step of a volume's ray march: the smallest spacing of the
// uploaded level over the samples per voxel.
double march_step(const Vec3& level_spacing, const VolumeSettings& s) {
  return std::min({level_spacing[0], level_spacing[1], level_spacing[2]}) / s.samples_per_voxel;
}

}  // namespace

std::shared_ptr<const GlTexture> VolumeTextureCache::preintegration(const Volume& volume,
                                                                    double step) {
  for (auto it = tables_.begin(); it != tables_.end(); ++it) {
    // The table is made from the transfer function itself (not its
    // 1024-texel table), its intensity and the step.
    if (it->step == step && it->intensity == volume.intensity && it->transfer == volume.transfer) {
      tables_.splice(tables_.begin(), tables_, it);
      return tables_.front().texture;
    }
  }
  tables_.push_front(
      {volume.transfer, volume.intensity, step, upload_preintegration(volume, step)});
  while (tables_.size() > 2 * max_entries_) tables_.pop_back();
  return tables_.front().texture;
}

std::shared_ptr<const VolumeTextures> VolumeTextureCache::get(const Volume& volume,
                                                              const VolumeSettings& settings) {
  const std::vector<float> tf = transfer_texels(volume);
  const int level = settings.level;
  const VolumePyramid pyramid = level > 0 ? settings.pyramid : VolumePyramid::kAverage;
  for (auto it = entries_.begin(); it != entries_.end();) {
    if (it->grid.expired()) {  // its scene is gone: so are its textures
      it = entries_.erase(it);
      continue;
    }
    if (it->grid_id == volume.grid.get() && it->level == level && it->pyramid == pyramid &&
        it->transfer == tf) {
      entries_.splice(entries_.begin(), entries_, it);
      return entries_.front().textures;
    }
    ++it;
  }
  VolumeSettings s = settings;
  s.pyramid = pyramid;
  entries_.push_front(
      {volume.grid, volume.grid.get(), level, pyramid, tf, upload_volume(volume, s, tf)});
  while (entries_.size() > max_entries_) entries_.pop_back();
  return entries_.front().textures;
}

void VolumeTextureCache::drop_unused() {
  entries_.remove_if([](const Entry& e) { return e.grid.expired(); });
}

VolumeResources::VolumeResources(const Scene& scene, VolumeTextureCache* cache) {
  for (const Volume& vol : scene.volumes) {
    Uploaded u;
    u.volume = &vol;
    u.gpu = cache ? cache->get(vol, scene.volume)
                  : upload_volume(vol, scene.volume, transfer_texels(vol));
    // The level spans the same box, voxel centre to voxel centre.
    for (int a = 0; a < 3; ++a) {
      u.spacing[a] =
          vol.spacing[a] * (vol.grid->dims[a] - 1) / static_cast<double>(u.gpu->dims[a] - 1);
    }
    if (preintegrated(scene.volume)) {
      const double step = march_step(u.spacing, scene.volume);
      u.preintegration =
          cache ? cache->preintegration(vol, step) : upload_preintegration(vol, step);
    }
    volumes_.push_back(std::move(u));
  }
}

void set_volume_box(ProgramPair& program, bool multiview, const FrameContext& ctx, int view) {
  Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (const Volume& v : ctx.scene.volumes) {
    Vec3 a, b;
    v.world_bounds(&a, &b);
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], a[k]);
      hi[k] = std::max(hi[k], b[k]);
    }
  }
  const Vec3& eye = view_eye(ctx, view);
  const Vec3 l = lo - eye, h = hi - eye;
  glUniform3f(program.uniform(multiview, "u_volume_lo"), static_cast<float>(l[0]),
              static_cast<float>(l[1]), static_cast<float>(l[2]));
  glUniform3f(program.uniform(multiview, "u_volume_hi"), static_cast<float>(h[0]),
              static_cast<float>(h[1]), static_cast<float>(h[2]));
}

namespace {

// Rotation matrix (row-major) of a unit quaternion (w, x, y, z).
std::array<double, 9> rotation_matrix(const std::array<double, 4>& q) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  return {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
          2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
          2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
}

class VolumePass final : public Pass {
 public:
  explicit VolumePass(bool knots) : knots_(knots) {}
  void execute(FrameContext& ctx, const PassDecl& self) override {
    const VolumeResources* res = ctx.resources.volumes();
    if (!res) throw GlError("volume pass: the scene's volumes were not uploaded");
    const VolumeSettings& s = ctx.scene.volume;
    const bool knots = knots_;
    const bool multi = ctx.views > 0;
    const bool surfaces = ctx.plan.written(TargetId::kViewDepth);
    bind_view_target_or_placeholder(ctx, 0, TargetId::kViewDepth);
    // hdr = volume colour + (1 - volume opacity) hdr, hdr's alpha kept; the
    // transmittance knots multiplied over the volumes.
    glEnable(GL_BLEND);
    glBlendFuncSeparatei(0, GL_ONE, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
    glBlendFuncSeparatei(1, GL_ZERO, GL_SRC_COLOR, GL_ZERO, GL_SRC_ALPHA);
    glBlendFuncSeparatei(2, GL_ZERO, GL_SRC_COLOR, GL_ZERO, GL_SRC_ALPHA);
    glBlendEquation(GL_FUNC_ADD);
    glDisable(GL_DEPTH_TEST);
    glBindVertexArray(ctx.empty_vao);

    // Back to front by the distance of each box's centre from the (first)
    // eye, so a nearer volume is composited over a farther one.
    std::vector<std::size_t> order(res->volumes().size());
    std::iota(order.begin(), order.end(), 0);
    std::vector<double> dist(order.size());
    for (std::size_t i = 0; i < order.size(); ++i) {
      Vec3 lo, hi;
      res->volumes()[i].volume->world_bounds(&lo, &hi);
      dist[i] = length(0.5 * (lo + hi) - ctx.basis.eye);
    }
    std::sort(order.begin(), order.end(),
              [&](std::size_t a, std::size_t b) { return dist[a] > dist[b]; });

    for (std::size_t i : order) {
      const VolumeResources::Uploaded& u = res->volumes()[i];
      const Volume& vol = *u.volume;
      // Skipping where some brick is empty (a dense volume's march would pay
      // for the test and skip nothing).
      ProgramPair& program = program_for(preintegrated(s), s.skip_empty && u.gpu->any_empty, knots);
      glUseProgram(program.get(multi));
      glUniform1i(program.uniform(multi, "u_has_surfaces"), surfaces ? 1 : 0);
      glUniform1f(program.uniform(multi, "u_ert"), static_cast<float>(s.ert_threshold));
      glUniform1i(program.uniform(multi, "u_jitter"), s.jitter ? 1 : 0);
      const std::array<double, 9> r = rotation_matrix(vol.rotation);
      float rot[9];
      for (int k = 0; k < 9; ++k) rot[k] = static_cast<float>(r[k]);
      // mat3 from row-major: transpose on upload.
      glUniformMatrix3fv(program.uniform(multi, "u_rotation"), 1, GL_TRUE, rot);
      glUniform3f(program.uniform(multi, "u_spacing"), static_cast<float>(u.spacing[0]),
                  static_cast<float>(u.spacing[1]), static_cast<float>(u.spacing[2]));
      glUniform3f(program.uniform(multi, "u_dims"), static_cast<float>(u.gpu->dims[0]),
                  static_cast<float>(u.gpu->dims[1]), static_cast<float>(u.gpu->dims[2]));
      const double step = march_step(u.spacing, s);
      glUniform1f(program.uniform(multi, "u_step"), static_cast<float>(step));
      // Opacity of a sample: corrected for its segment's length, or the
      // seed's fixed per-sample opacity (the one the default step, level 0,
      // gets): too transparent when the step grows.
      const double base_step = std::min({vol.spacing[0], vol.spacing[1], vol.spacing[2]}) /
                               VolumeSettings{}.samples_per_voxel;
      glUniform1f(program.uniform(multi, "u_opacity_unit"),
                  static_cast<float>(vol.transfer.opacity_unit));
      glUniform1f(
          program.uniform(multi, "u_fixed_exponent"),
          s.opacity_correction ? -1.0f : static_cast<float>(base_step / vol.transfer.opacity_unit));
      glBindTextureUnit(1, u.gpu->values.get());
      glBindTextureUnit(2, u.gpu->transfer.get());
      glBindTextureUnit(3, u.gpu->bricks.get());
      glBindTextureUnit(4, u.preintegration ? u.preintegration->get()
                                            : ctx.targets.placeholder(GL_TEXTURE_2D));
      int view = 0;
      for_each_view_offset(ctx, self, program, "u_origin", vol.origin, [&] {
        set_volume_box(program, multi, ctx, view++);
        draw_arrays(GL_TRIANGLES, 0, 3);
      });
    }
    glBlendFunc(GL_ONE, GL_ONE);  // every attachment's state back to one value
    glDisable(GL_BLEND);
    gl_check("volume pass");
  }

 private:
  // The march's programs: shaders/programs.txt "volume_cast[_preint][_skip][_knots]".
  ProgramPair& program_for(bool preint, bool skip, bool knots) {
    return programs_.get(std::string("volume_cast") + (preint ? "_preint" : "") +
                         (skip ? "_skip" : "") + (knots ? "_knots" : ""));
  }
  bool knots_;  // the row with beams: also writes the transmittance knots
  LazyPrograms programs_;
};

}  // namespace

std::unique_ptr<Pass> make_volume_pass(bool knots) { return std::make_unique<VolumePass>(knots); }

}  // namespace beamcast
