// How the TSDF integrator reads a voxel's depth from the 2 x 2 pixels around its projection:
// interpolated on planes, the nearest pixel across depth edges, the two planes meeting there
// across a crease, found by its window's kinks or, under depth noise, summed along its line
// (issue 22, defect 4).
#pragma once

#include <cstdint>
#include <vector>

namespace downstream_perception {

/// Per 2 x 2 pixel window (indexed by its top-left pixel).
enum class DepthWindow : std::uint8_t {
  kNearestPixel = 0,  ///< an invalid pixel or a depth edge (or the image's last row / column)
  kInterpolate = 1,   ///< on one plane: inverse depth bilinear between the four (exact there)
  /// Continuous, but bent beyond the frame's noise, more across its rows than across its
  /// columns: a crease runs between its rows (creaseInverseDepth).
  kCreaseBetweenRows = 2,
  kCreaseBetweenColumns = 3,  ///< ... between its columns
};

struct DepthWindowSettings {
  float max_step = 0.0f;  ///< m; four depths spanning more are a depth edge
  /// m; a window bent less than this from a plane is one (above float rounding, below what a
  /// voxel resolves)
  float crease_min = 0.0f;
  /// Bent more than this many times the frame's median bend to be a crease: under noise a
  /// plane's windows are bent too.
  float crease_noise_factor = 4.0f;
  /// Also sum each window's slope change over this many lines on each side along the crease
  /// (0: off): a crease under depth noise (depth_windows.cpp, summedSlopeChanges).
  int crease_sum_radius = 0;
  /// A summed slope change beyond this many times the frame's median one is a crease (Gaussian
  /// noise: 6 x the median |value| is 4 sigma, 6e-5 of a plane's windows).
  float crease_sum_noise_factor = 6.0f;
};

/// Scratch reused from frame to frame.
struct DepthWindowScratch {
  std::vector<float> kink_row;     ///< per pixel, inverse depth (depth_windows.cpp)
  std::vector<float> kink_column;  ///< per pixel, inverse depth
  std::vector<float> sample;       ///< every kNoiseStride-th continuous window's bend
  std::vector<float> line_ring;    ///< the last 2 r + 3 rows' slope changes along the rows (m)
  std::vector<float> line;         ///< one row's slope changes along the columns (m)
};

/// Every window's class into out (w x h). A window's bend (m) is how far from a plane its
/// pixels lie: the larger of its twist and, along its rows and columns, its pixels' kinks
/// (second differences of inverse depth; a crease along the rows or columns has no twist),
/// times z^2; 0 on a plane (depth_windows.cpp, windowBend). Returns the threshold: max(
/// crease_min, crease_noise_factor x the median bend of every kNoiseStride-th continuous
/// window); on a plane under independent depth noise about 5e-5 of the windows bend more than
/// 4 x the median (simulated). Where that threshold lies above crease_min (noise governs it) and
/// crease_sum_radius > 0, a plane window whose slope change summed along 2 r + 2 lines exceeds
/// crease_sum_noise_factor x the median |sum|, and is the largest across the lines, is a crease
/// too (a crease's kink adds up along its line, the noise as the square root). depth: m (NaN or
/// +Inf: invalid); inverse: 1 / depth, 0 where invalid.
float classifyDepthWindows(const float* depth, const float* inverse, int w, int h,
                           const DepthWindowSettings& settings, DepthWindowScratch* scratch,
                           DepthWindow* out);

/// The two planes meeting at a crease, read at a point of its window (creaseInverseDepth).
struct CreaseDepth {
  float inverse = 0.0f;  ///< 1 / m; 0: none (a pixel it needs is outside the image or invalid)
  bool concave = false;  ///< a concave crease (a room's corner): inverse depth is convex there
};

/// The inverse depth at (u0 + a, v0 + b), a, b in [0, 1), in the crease window (u0, v0) of
/// class `kind`: each side's plane, from the two pixels on that side in each of the window's
/// two columns (kCreaseBetweenRows: rows v0 - 1, v0 and v0 + 1, v0 + 2; rows for the other
/// class), extended to the point; the larger of the two (across a concave crease the surface
/// seen is the nearer plane: inverse depth is convex there) or the smaller (a convex crease),
/// as the second differences say. Exact for two planes meeting between the window's rows,
/// where the bilinear interpolation is a chord across the corner (nearer than both planes at a
/// concave one, farther at a convex one). None where an outer pixel lies more than max_step
/// (m) from its neighbour (a depth edge) or is invalid.
CreaseDepth creaseInverseDepth(const float* inverse, int w, int h, int u0, int v0, float a, float b,
                               DepthWindow kind, float max_step);

/// Windows; odd, so the sample spreads over rows and columns (10,000 windows at 640 x 480).
constexpr int kNoiseStride = 31;

}  // namespace downstream_perception
