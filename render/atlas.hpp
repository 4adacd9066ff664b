// Atlas images: K frames tiled into one image, for clients that want one
// picture of a rig (PROTOCOL.md, render param "atlas"). No GL.
//
// Layout: columns = ceil(sqrt(K)), rows = ceil(K / columns); every cell is as
// large as the largest frame (max width x max height); frame i sits in row
// i / columns, column i % columns, counted from the top left, at the cell's
// top-left corner. Cells without a frame, and the part of a cell a smaller
// frame leaves, are black.
#pragma once

#include <vector>

#include "render/image.hpp"

namespace beamcast {

struct AtlasTile {
  int x = 0, y = 0;  // top-left pixel of the frame in the atlas (y from the top)
  int width = 0, height = 0;
};

struct Atlas {
  Image image;
  int columns = 0, rows = 0, cell_width = 0, cell_height = 0;
  std::vector<AtlasTile> tiles;  // one per frame, in frame order
};

// Frames must share a bit depth and be non-empty.
Atlas make_atlas(const std::vector<const Image*>& frames);

}  // namespace beamcast
