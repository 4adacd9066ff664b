#include "protocol/volume_files.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>

#include "protocol/json_reader.hpp"
#include "protocol/volume_formats/format_support.hpp"

namespace beamcast {

using json_read::fail;
using volume_io::bad;
using volume_io::dims_text;
using volume_io::read_plain_payload;

namespace {

// Calls fn(index, value) for every sample, in memory order, swapping bytes
// where the file's order is not the machine's.
template <class T, class F>
void each_as(const VolumeFileData& d, F&& fn) {
  constexpr std::size_t kSize = sizeof(T);
  const bool swap = d.big_endian != (std::endian::native == std::endian::big);
  const std::size_t n = d.bytes.size() / kSize;
  const unsigned char* p = d.bytes.data();
  for (std::size_t i = 0; i < n; ++i, p += kSize) {
    unsigned char b[kSize];
    std::memcpy(b, p, kSize);
    if (swap) std::reverse(b, b + kSize);
    T v;
    std::memcpy(&v, b, kSize);
    fn(i, static_cast<double>(v));
  }
}

template <class F>
void each_sample(const VolumeFileData& d, F&& fn) {
  switch (d.type) {
    case VolumeSampleType::kU8:
      return each_as<std::uint8_t>(d, fn);
    case VolumeSampleType::kI8:
      return each_as<std::int8_t>(d, fn);
    case VolumeSampleType::kU16:
      return each_as<std::uint16_t>(d, fn);
    case VolumeSampleType::kI16:
      return each_as<std::int16_t>(d, fn);
    case VolumeSampleType::kU32:
      return each_as<std::uint32_t>(d, fn);
    case VolumeSampleType::kI32:
      return each_as<std::int32_t>(d, fn);
    case VolumeSampleType::kF32:
      return each_as<float>(d, fn);
    case VolumeSampleType::kF64:
      return each_as<double>(d, fn);
  }
}

}  // namespace

std::size_t sample_size(VolumeSampleType t) {
  switch (t) {
    case VolumeSampleType::kU8:
    case VolumeSampleType::kI8:
      return 1;
    case VolumeSampleType::kU16:
    case VolumeSampleType::kI16:
      return 2;
    case VolumeSampleType::kU32:
    case VolumeSampleType::kI32:
    case VolumeSampleType::kF32:
      return 4;
    case VolumeSampleType::kF64:
      return 8;
  }
  return 1;
}

std::string_view sample_type_name(VolumeSampleType t) {
  switch (t) {
    case VolumeSampleType::kU8:
      return "uint8";
    case VolumeSampleType::kI8:
      return "int8";
    case VolumeSampleType::kU16:
      return "uint16";
    case VolumeSampleType::kI16:
      return "int16";
    case VolumeSampleType::kU32:
      return "uint32";
    case VolumeSampleType::kI32:
      return "int32";
    case VolumeSampleType::kF32:
      return "float32";
    case VolumeSampleType::kF64:
      return "float64";
  }
  return "?";
}

bool is_float(VolumeSampleType t) {
  return t == VolumeSampleType::kF32 || t == VolumeSampleType::kF64;
}

std::array<int, 3> check_volume_dims(const std::array<std::int64_t, 3>& dims, const VoxelBudget& budget,
                                     const std::string& what,
                                     const std::array<std::string, 3>& axis_paths,
                                     const std::string& path) {
  for (int a = 0; a < 3; ++a) {
    if (dims[a] < 2) {
      fail("out_of_range", axis_paths[a],
           what + " " + dims_text(dims) +
               " must be at least 2 on every axis (the box spans voxel centre to centre)");
    }
  }
  std::int64_t product = dims[0];
  const bool overflow = __builtin_mul_overflow(product, dims[1], &product) ||
                        __builtin_mul_overflow(product, dims[2], &product);
  const std::string limit = "max_volume_voxels = " + std::to_string(budget.limit);
  if (overflow) {
    fail("limit_exceeded", path,
         what + " " + dims_text(dims) +
             " make more voxels than a 64-bit integer holds, far over the limit " + limit);
  }
  if (product > budget.left) {
    const std::int64_t used = budget.limit - budget.left;
    fail(
        "limit_exceeded", path,
        what + " " + dims_text(dims) + " make " + std::to_string(product) + " voxels" +
            (used > 0 ? " (and the scene's other volumes have " + std::to_string(used) + ")" : "") +
            ", over the limit " + limit + " per scene");
  }
  std::array<int, 3> out{};
  for (int a = 0; a < 3; ++a) {
    if (dims[a] > kMaxVolumeDimension) {
      fail("out_of_range", axis_paths[a],
           what + " " + dims_text(dims) + " exceed " + std::to_string(kMaxVolumeDimension) +
               " voxels on an axis (limit max_volume_dimension)");
    }
    out[a] = static_cast<int>(dims[a]);
  }
  return out;
}

VolumeFileData read_raw_volume(const VolumeFileRef& f, const std::array<int, 3>& dims,
                               VolumeSampleType type, bool big_endian) {
  VolumeFileData d;
  d.dims = dims;
  d.type = type;
  d.big_endian = big_endian;
  d.bytes = read_plain_payload(f, 0, dims, type);
  return d;
}

std::array<double, 2> volume_data_range(const VolumeFileData& d, const VolumeFileRef& f) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  std::optional<std::size_t> bad_index;  // the first non-finite sample
  double bad_value = 0.0;
  each_sample(d, [&](std::size_t i, double v) {
    if (!std::isfinite(v)) {
      if (!bad_index) {
        bad_index = i;
        bad_value = v;
      }
      return;
    }
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  });
  if (bad_index) {
    const std::size_t nx = static_cast<std::size_t>(d.dims[0]),
                      ny = static_cast<std::size_t>(d.dims[1]);
    bad(f, "has a " + std::string(std::isnan(bad_value) ? "NaN" : "infinite") + " voxel: index " +
               std::to_string(*bad_index) + " (x " + std::to_string(*bad_index % nx) + ", y " +
               std::to_string(*bad_index / nx % ny) + ", z " +
               std::to_string(*bad_index / nx / ny) + "); voxel values must be finite");
  }
  return {lo, hi};
}

std::shared_ptr<const VolumeGrid> normalize_volume(const VolumeFileData& d,
                                                   const std::array<double, 2>& range) {
  auto g = std::make_shared<VolumeGrid>();
  g->dims = d.dims;
  g->values.resize(static_cast<std::size_t>(g->voxels()));
  const double lo = range[0], width = range[1] - range[0];
  each_sample(d, [&](std::size_t i, double v) {
    g->values[i] =
        static_cast<std::uint16_t>(std::lround(std::clamp((v - lo) / width, 0.0, 1.0) * 65535.0));
  });
  return g;
}

}  // namespace beamcast
