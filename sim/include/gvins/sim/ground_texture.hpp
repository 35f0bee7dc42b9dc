// A procedural, multi-scale, seeded texture of the ground plane z = 0 of W, prefiltered for
// rendering at any distance (a mip-map generated tile by tile on demand).
//
// Content: octaves of random shapes (rotated rectangles, ellipses, triangles) with cell sizes
// c_o = finestFeature 2^o, one shape per cell with probability 0.8, each adding or removing a
// random amount of brightness; sharp straight edges and corners at every scale, like fields,
// roofs, roads, rocks and vegetation seen from above, so corner detectors and KLT find
// features at any flight height. Everything derives from hashes of (seed, octave, cell), so the
// texture is identical however and in whatever order it is queried.
//
// Mip levels: level l has texels of size s_l = texelSize 2^l centred at ((i + 1/2) s_l,
// (j + 1/2) s_l). A texel holds the shapes box-filtered over its footprint (edge coverage
// ramps over one texel) and only the octaves that the level resolves (weight smoothly 0 -> 1
// as c_o / s_l goes 2 -> 4), which approximates the average of the finer levels; sample()
// interpolates bilinearly within a level and linearly between levels (trilinear filtering).
//
// An optional checkerboard calibration target (white border one square wide) can be laid on
// the ground; it is filtered exactly (the box filter of a separable square wave).
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

namespace gvins::sim {

struct CheckerboardConfig {
  bool enabled = false;
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();  ///< W x,y of the first inner corner (m)
  double yawDeg = 0.0;     ///< rotation of the board's x axis from W's x axis (counter-clockwise)
  int innerCols = 8;       ///< inner corners along the board's x axis
  int innerRows = 6;
  double square = 0.5;     ///< m
  double dark = 20.0, bright = 235.0;  ///< gray levels
  /// W x,y of inner corner (i, j), i < innerCols, j < innerRows.
  Eigen::Vector2d corner(int i, int j) const;
};

struct GroundTextureConfig {
  std::uint64_t seed = 1;
  double texelSize = 0.01;       ///< m, finest mip level
  int levels = 16;               ///< mip levels (texel sizes texelSize * 2^l)
  double finestFeature = 0.04;   ///< m, cell size of the finest shape octave
  int octaves = 12;              ///< shape octaves (cells up to finestFeature 2^(octaves-1))
  double mean = 115.0;           ///< mean gray level
  double amplitude = 26.0;       ///< brightness step of one shape (gray levels, before clamping)
  CheckerboardConfig board;
  std::size_t cacheBytes = std::size_t{768} << 20;  ///< tile cache limit

  /// Throws std::invalid_argument for non-positive sizes or counts outside [1, 24].
  void validate() const;
};

class GroundTexture {
 public:
  static constexpr int kTileSize = 128;  ///< texels per tile side (plus one apron texel)

  /// One tile of a mip level: (kTileSize + 1)^2 texels, the last row/column duplicating the
  /// first of the neighbouring tile, so bilinear lookups stay within one tile.
  struct Tile {
    int level = 0;
    std::int64_t tx = 0, ty = 0;
    std::vector<float> texels;  ///< row-major, stride kTileSize + 1
  };

  explicit GroundTexture(const GroundTextureConfig& config);

  const GroundTextureConfig& config() const { return cfg_; }
  int levels() const { return cfg_.levels; }
  double texelSize(int level) const { return texel_[static_cast<std::size_t>(level)]; }

  /// Texel value of level l at integer texel (i, j), computed directly (no cache).
  float texel(int level, std::int64_t i, std::int64_t j) const;
  /// Tile (generated on first use, then cached; thread-safe).
  std::shared_ptr<const Tile> tile(int level, std::int64_t tx, std::int64_t ty) const;
  /// Bilinear sample of one level at W (x, y).
  float sampleLevel(double x, double y, int level) const;
  /// Trilinear sample at W (x, y) for a continuous level (clamped to [0, levels - 1]).
  float sample(double x, double y, double level) const;
  /// Level whose texels match a footprint of `size` metres: log2(size / texelSize).
  double levelForFootprint(double size) const;

  /// Tiles generated so far and bytes held in the cache.
  std::size_t tilesGenerated() const;
  std::size_t cachedBytes() const;

 private:
  void renderTile(Tile& t) const;
  GroundTextureConfig cfg_;
  std::vector<double> texel_;
  struct Entry {
    std::shared_ptr<const Tile> tile;
    std::uint64_t lastUse = 0;
  };
  mutable std::mutex mutex_;
  mutable std::unordered_map<std::uint64_t, Entry> cache_;
  mutable std::uint64_t useCounter_ = 0;
  mutable std::size_t generated_ = 0;
};

}  // namespace gvins::sim
