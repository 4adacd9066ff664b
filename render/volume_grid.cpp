#include "render/volume_grid.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "render/gl_validate.hpp"
#include "render/passes.hpp"
#include "render/scene_resources.hpp"

namespace beamcast {

namespace {

// The [lo, hi] of one axis holding all but kGridOutlierShare of the photons
// at each end.
std::array<double, 2> axis_range(const std::vector<Photon>& photons, int axis) {
  std::vector<float> v(photons.size());
  for (std::size_t i = 0; i < photons.size(); ++i) v[i] = photons[i].p[axis];
  const auto skip = static_cast<std::size_t>(kGridOutlierShare * static_cast<double>(v.size()));
  auto lo = v.begin() + static_cast<std::ptrdiff_t>(skip);
  auto hi = v.end() - 1 - static_cast<std::ptrdiff_t>(skip);
  std::nth_element(v.begin(), lo, v.end());
  const double a = *lo;
  std::nth_element(v.begin(), hi, v.end());
  return {a, static_cast<double>(*hi)};
}

int round_up(int n, int m) { return (n + m - 1) / m * m; }

}  // namespace

VolumeGridBins bin_volume_photons(const std::vector<Photon>& photons, const MediumField& field,
                                  double radius, const Aabb& scene) {
  VolumeGridBins out;
  VolumeGridLayout& g = out.layout;
  if (!(radius > 0.0) || !std::isfinite(radius)) radius = 1.0;
  g.cell = kGridCellPerRadius * radius;
  Vec3 lo{0.0, 0.0, 0.0}, hi{0.0, 0.0, 0.0};
  if (!photons.empty()) {
    for (int k = 0; k < 3; ++k) {
      const auto r = axis_range(photons, k);
      lo[k] = r[0];
      hi[k] = r[1];
    }
  }
  if (!scene.empty()) {
    // Within the scene's box and its largest side beyond it each way:
    // photons that flew farther out are not binned.
    const Vec3 s = scene.hi - scene.lo;
    const double margin = kGridSceneMargin * std::max({s[0], s[1], s[2]});
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::max(lo[k], scene.lo[k] - margin);
      hi[k] = std::min(hi[k], scene.hi[k] + margin);
      if (hi[k] < lo[k]) hi[k] = lo[k];
    }
  }
  // The cell grows until the box fits in kMaxGridCells (sides rounded up
  // to kGridSideMultiple).
  for (;;) {
    std::int64_t cells = 1;
    for (int k = 0; k < 3; ++k) {
      const double span = std::max(hi[k] - lo[k], 0.0);
      const int n = static_cast<int>(std::min(std::ceil(span / g.cell) + 1.0, 1e6));
      g.dims[static_cast<std::size_t>(k)] = round_up(std::max(n, 1), kGridSideMultiple);
      cells *= g.dims[static_cast<std::size_t>(k)];
    }
    if (cells <= kMaxGridCells) break;
    g.cell *= std::cbrt(static_cast<double>(cells) / static_cast<double>(kMaxGridCells)) * 1.01;
  }
  // The grid centred on the box.
  for (int k = 0; k < 3; ++k) {
    const double side = g.cell * g.dims[static_cast<std::size_t>(k)];
    g.origin[k] = 0.5 * (lo[k] + hi[k]) - 0.5 * side;
  }
  const std::int64_t cells = g.cells();
  // Counting sort by cell; -1: outside.
  std::vector<std::int64_t> cell_of(photons.size(), -1);
  std::vector<std::uint32_t> count(static_cast<std::size_t>(cells) + 1, 0);
  for (std::size_t i = 0; i < photons.size(); ++i) {
    std::int64_t c = 0;
    bool inside = true;
    for (int k = 2; k >= 0; --k) {
      const double x = (photons[i].p[k] - g.origin[k]) / g.cell;
      const int n = g.dims[static_cast<std::size_t>(k)];
      if (!(x >= 0.0 && x < n)) {
        inside = false;
        break;
      }
      c = c * n + static_cast<std::int64_t>(x);
    }
    if (!inside) {
      ++out.dropped;
      continue;
    }
    cell_of[i] = c;
    ++count[static_cast<std::size_t>(c) + 1];
  }
  for (std::size_t c = 1; c < count.size(); ++c) count[c] += count[c - 1];
  out.starts = count;
  out.photons.resize(photons.size() - out.dropped);
  for (std::size_t i = 0; i < photons.size(); ++i) {
    if (cell_of[i] < 0) continue;
    VolumeGridPhoton& d = out.photons[count[static_cast<std::size_t>(cell_of[i])]++];
    const Photon& p = photons[i];
    for (int k = 0; k < 3; ++k) {
      d.position[k] = static_cast<float>(p.p[k] - g.origin[k]);
      d.power[k] = p.power[k];
      d.dir[k] = p.dir[k];
    }
    d.position[3] = static_cast<float>(field.k(Vec3{p.p[0], p.p[1], p.p[2]}));
    d.power[3] = 0.0f;
    const auto index = static_cast<std::uint32_t>(i);
    std::memcpy(&d.dir[3], &index, sizeof index);
  }
  return out;
}

VolumeGridResources::VolumeGridResources(const VolumeGridBins& bins)
    : layout_(bins.layout),
      count_(static_cast<GLsizei>(bins.photons.size())),
      dropped_(bins.dropped) {
  // An empty buffer is not allowed (glNamedBufferStorage size 0): one
  // unread record stands in.
  const VolumeGridPhoton none{};
  photons_ = bins.photons.empty() ? make_buffer(sizeof none, &none) : make_buffer(bins.photons);
  starts_ = make_buffer(bins.starts);
  const auto& d = layout_.dims;
  int side = std::min({d[0], d[1], d[2]});
  levels_ = 1;
  while (levels_ < 4 && (side & 1) == 0) {
    side >>= 1;
    ++levels_;
  }
  // Storage for the whole chain (a mipmap filter samples a complete
  // texture), of which only the first levels_ are exact averages and read.
  int chain = 1;
  for (int n = std::max({d[0], d[1], d[2]}); n > 1; n >>= 1) ++chain;
  GLuint id = 0;
  glCreateTextures(GL_TEXTURE_3D, 1, &id);
  texture_ = GlTexture(id);
  glTextureStorage3D(id, chain, GL_RGBA32F, d[0], d[1], d[2]);
  glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  // Outside the grid nothing: the border cells' light fades over the half
  // cell beyond them (the march reaches that far).
  for (GLenum wrap : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R}) {
    glTextureParameteri(id, wrap, GL_CLAMP_TO_BORDER);
  }
  const float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  glTextureParameterfv(id, GL_TEXTURE_BORDER_COLOR, zero);
  gl_check("volume grid upload");
}

namespace {

// Level of detail (gi.lod) for the grid: the seed's share Q of the detail
// dropped at distance D (smoothstep(near, far, D), or 1 - smoothstep(far,
// near, D) when near > far) reads the grid at level log2(1 / (1 - Q))
// (a 2 x 2 x 2 average per level; capped at the coarsest) with steps as
// much longer. No photon is dropped, so no light is lost.
void set_grid_lod(ProgramPair& program, bool multi, const GiSettings& gi, int levels) {
  glUniform1i(program.uniform(multi, "u_lod"), gi.lod_groups > 0 && levels > 1 ? 1 : 0);
  glUniform1f(program.uniform(multi, "u_lod_near"), static_cast<float>(gi.lod_near));
  glUniform1f(program.uniform(multi, "u_lod_far"), static_cast<float>(gi.lod_far));
  glUniform1f(program.uniform(multi, "u_max_level"), static_cast<float>(levels - 1));
}

class VolumeGridPass final : public Pass {
 public:
  VolumeGridPass() : bin_("volume_grid_bin"), programs_("volume_grid") {}
  void execute(FrameContext& ctx, const PassDecl& self) override {
    if (!ctx.scene.has_medium()) throw GlError("volume grid pass: the scene has no medium");
    const VolumeGridResources* grid = ctx.resources.volume_grid();
    if (!grid) throw GlError("volume grid pass: the plan uploaded no grid");
    const VolumeGridLayout& g = grid->layout();
    const double share = display_share(ctx.scene.gi.display_fraction);
    const double total = static_cast<double>(grid->photon_count()) +
                         static_cast<double>(grid->dropped());
    const auto drawn = static_cast<GLint>(std::llround(share * total));
    const bool lod = ctx.scene.gi.lod_groups > 0 && grid->levels() > 1;
    const bool multi = ctx.views > 0;

    // The binning program (per view: the phase looks at that view's eye).
    const GLuint bin = bin_.get(false);
    glUseProgram(bin);
    glUniform3i(bin_.uniform(false, "u_dims"), g.dims[0], g.dims[1], g.dims[2]);
    glUniform1i(bin_.uniform(false, "u_drawn"), drawn);
    glUniform1f(bin_.uniform(false, "u_scale"),
                static_cast<float>(1.0 / (share * g.cell * g.cell * g.cell)));
    const GLint bin_offset = bin_.uniform(false, "u_offset");
    const GLint bin_ortho = bin_.uniform(false, "u_ortho_dir");

    ProgramPair& march = programs_.get(ctx.scene);
    glUseProgram(march.get(multi));
    glUniform1i(march.uniform(multi, "u_has_surfaces"), ctx.plan.written(TargetId::kViewDepth) ? 1 : 0);
    glUniform3f(march.uniform(multi, "u_grid_size"), static_cast<float>(g.cell * g.dims[0]),
                static_cast<float>(g.cell * g.dims[1]), static_cast<float>(g.cell * g.dims[2]));
    glUniform1f(march.uniform(multi, "u_cell"), static_cast<float>(g.cell));
    set_grid_lod(march, multi, ctx.scene.gi, grid->levels());
    const GLint region_eye = set_medium_uniforms(march, multi, ctx);
    const GLint march_offset = march.uniform(multi, "u_grid_offset");

    bind_view_target_or_placeholder(ctx, 0, TargetId::kViewDepth);
    glBindTextureUnit(1, grid->texture());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, grid->photon_buffer());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, grid->start_buffer());
    const GLuint groups = static_cast<GLuint>((g.cells() + 63) / 64);
    int view = 0;
    for_each_view(ctx, self, march, [&] {
      const int v = multi ? view : -1;
      // Bin: every cell's sum p(mu) power / volume towards this view's eye.
      glUseProgram(bin);
      set_view_offset(ctx, bin_offset, v, g.origin);
      const Camera& cam = multi ? (*ctx.view_cameras)[static_cast<std::size_t>(view)] : ctx.camera;
      const CameraBasis& basis =
          multi ? (*ctx.view_bases)[static_cast<std::size_t>(view)] : ctx.basis;
      // Orthographic: every ray's direction to the eye is -forward (0: perspective).
      const double o = cam.projection == Projection::kOrthographic ? -1.0 : 0.0;
      glUniform3f(bin_ortho, static_cast<float>(o * basis.forward[0]),
                  static_cast<float>(o * basis.forward[1]),
                  static_cast<float>(o * basis.forward[2]));
      glBindImageTexture(0, grid->texture(), 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA32F);
      dispatch_compute(groups, 1, 1);
      glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
      if (lod) glGenerateTextureMipmap(grid->texture());
      // March: each pixel's view ray through the grid, added to hdr.
      glUseProgram(march.get(multi));
      set_view_offset(ctx, march_offset, v, g.origin);
      set_region_eye(ctx, region_eye, view);
      begin_additive(ctx);
      draw_arrays(GL_TRIANGLES, 0, 3);
      ++view;
    });
    glDisable(GL_BLEND);
    gl_check("volume grid pass");
  }

 private:
  ProgramPair bin_;
  RegionProgram programs_;
};

}  // namespace

std::unique_ptr<Pass> make_volume_grid_pass() { return std::make_unique<VolumeGridPass>(); }

}  // namespace beamcast
