#include "render/atlas.hpp"

#include "protocol/check.hpp"
#include "protocol/scene_json.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace beamcast {

Atlas make_atlas(const std::vector<const Image*>& frames) {
  BEAMCAST_CHECK(!frames.empty(), "make_atlas: no frames");
  Atlas a;
  const int k = static_cast<int>(frames.size());
  std::vector<std::pair<int, int>> sizes;
  for (const Image* f : frames) {
    BEAMCAST_CHECK(f->bit_depth == frames[0]->bit_depth, "make_atlas: frames of different bit depths");
    sizes.emplace_back(f->width, f->height);
  }
  const AtlasGrid g = atlas_grid(sizes);  // the grid the server checked against its limits
  a.columns = g.columns;
  a.rows = g.rows;
  a.cell_width = g.cell_width;
  a.cell_height = g.cell_height;
  Image& img = a.image;
  img.width = a.columns * a.cell_width;
  img.height = a.rows * a.cell_height;
  img.bit_depth = frames[0]->bit_depth;
  img.rgb.assign(3 * static_cast<std::size_t>(img.width) * img.height, 0);
  for (int i = 0; i < k; ++i) {
    const Image& f = *frames[i];
    AtlasTile t{(i % a.columns) * a.cell_width, (i / a.columns) * a.cell_height, f.width,
                f.height};
    for (int y = 0; y < f.height; ++y) {
      const auto src = f.rgb.begin() + 3 * static_cast<std::ptrdiff_t>(y) * f.width;
      std::copy(src, src + 3 * f.width,
                img.rgb.begin() + 3 * (static_cast<std::ptrdiff_t>(t.y + y) * img.width + t.x));
    }
    a.tiles.push_back(t);
  }
  return a;
}

}  // namespace beamcast
