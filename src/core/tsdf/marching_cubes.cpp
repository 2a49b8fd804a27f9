#include "downstream_perception/core/tsdf/marching_cubes.h"

#include <tsl/robin_set.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>

namespace downstream_perception {

const std::array<std::array<int, 3>, 8> kCubeCorners = {
    {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}};
const std::array<std::array<int, 2>, 12> kCubeEdges = {{{0, 1},
                                                        {1, 2},
                                                        {2, 3},
                                                        {3, 0},
                                                        {4, 5},
                                                        {5, 6},
                                                        {6, 7},
                                                        {7, 4},
                                                        {0, 4},
                                                        {1, 5},
                                                        {2, 6},
                                                        {3, 7}}};

namespace {

// Each face as its corners in cyclic order and the edges between consecutive corners
// (edge k joins corner k and corner k + 1 of the cycle).
struct Face {
  std::array<int, 4> corners;
  std::array<int, 4> edges;
};
constexpr std::array<Face, 6> kFaces = {{{{0, 1, 2, 3}, {0, 1, 2, 3}},
                                         {{4, 5, 6, 7}, {4, 5, 6, 7}},
                                         {{0, 1, 5, 4}, {0, 9, 4, 8}},
                                         {{1, 2, 6, 5}, {1, 10, 5, 9}},
                                         {{2, 3, 7, 6}, {2, 11, 6, 10}},
                                         {{3, 0, 4, 7}, {3, 8, 7, 11}}}};

Eigen::Vector3d edgeMidpoint(int e) {
  const auto& a = kCubeCorners[kCubeEdges[e][0]];
  const auto& b = kCubeCorners[kCubeEdges[e][1]];
  return 0.5 * Eigen::Vector3d(a[0] + b[0], a[1] + b[1], a[2] + b[2]);
}

bool shareFace(int ea, int eb) {
  for (const Face& f : kFaces) {
    const bool a = std::find(f.edges.begin(), f.edges.end(), ea) != f.edges.end();
    const bool b = std::find(f.edges.begin(), f.edges.end(), eb) != f.edges.end();
    if (a && b) return true;
  }
  return false;
}

Eigen::Vector3d cornerPoint(int c) {
  return {double(kCubeCorners[c][0]), double(kCubeCorners[c][1]), double(kCubeCorners[c][2])};
}

std::vector<std::array<int, 3>> deriveCase(int mask) {
  const auto inside = [mask](int c) { return ((mask >> c) & 1) != 0; };
  // One directed segment per face per crossing pair: walking from edge a to edge b, the
  // inside corner it cuts off lies to the side (b - a) x n_out points to (n_out: the face's
  // outward normal). A neighbouring cube sees the face with the opposite normal, so it walks
  // the same segment the other way: the surface is closed and consistently oriented by
  // construction, with triangle normals toward the outside corners (free space).
  std::array<int, 12> next;
  next.fill(-1);
  for (const Face& f : kFaces) {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (const int c : f.corners) centre += 0.25 * cornerPoint(c);
    const Eigen::Vector3d n_out = centre - Eigen::Vector3d::Constant(0.5);
    const auto segment = [&](int ka, int kb, int inside_corner) {
      const int ea = f.edges[ka], eb = f.edges[kb];
      const Eigen::Vector3d pa = edgeMidpoint(ea), pb = edgeMidpoint(eb);
      const Eigen::Vector3d side = (pb - pa).cross(n_out);
      const bool forward = side.dot(cornerPoint(inside_corner) - 0.5 * (pa + pb)) > 0.0;
      next[forward ? ea : eb] = forward ? eb : ea;
    };
    std::vector<int> crossing;  // positions k in the face cycle whose edge crosses
    for (int k = 0; k < 4; ++k) {
      if (inside(f.corners[k]) != inside(f.corners[(k + 1) % 4])) crossing.push_back(k);
    }
    if (crossing.size() == 2) {
      int in = -1;
      for (const int c : f.corners) {
        if (inside(c)) in = c;
      }
      segment(crossing[0], crossing[1], in);
    } else if (crossing.size() == 4) {
      // Ambiguous face: cut off each inside corner (edges k-1 and k meet at corner k).
      for (int k = 0; k < 4; ++k) {
        if (inside(f.corners[k])) segment((k + 3) % 4, k, f.corners[k]);
      }
    }
  }
  std::vector<std::array<int, 3>> triangles;
  std::array<bool, 12> used{};
  for (int start = 0; start < 12; ++start) {
    if (used[start] || next[start] < 0) continue;
    std::vector<int> loop;
    for (int e = start; !used[e]; e = next[e]) {
      used[e] = true;
      loop.push_back(e);
    }
    // Fan from an apex none of whose diagonals lies on a cube face: such a diagonal would be
    // shared with the neighbouring cube's triangles (a non-manifold edge on ambiguous faces).
    // Every loop of the 256 cases has one (a pinched edge would fail the random-field test).
    const std::size_t n = loop.size();
    std::size_t apex = 0;
    for (std::size_t i = 0; i < n && n > 3; ++i) {
      bool clean = true;
      for (std::size_t j = 0; j < n && clean; ++j) {
        if (j == i || j == (i + 1) % n || j == (i + n - 1) % n) continue;
        clean = !shareFace(loop[i], loop[j]);
      }
      if (clean) {
        apex = i;
        break;
      }
    }
    std::rotate(loop.begin(), loop.begin() + static_cast<std::ptrdiff_t>(apex), loop.end());
    for (std::size_t i = 1; i + 1 < n; ++i) {
      triangles.push_back({loop[0], loop[i], loop[i + 1]});
    }
  }
  return triangles;
}

// The block's cube corners (lattice 0 .. 8 per axis), the border their gradients read (-1 and
// 9) and, when missing voxels are extrapolated, the two voxels beyond it that extrapolation
// reads (-3 .. 11): the distances gathered from the 27 blocks around it once, NaN where a voxel
// is missing or lighter than min_weight, so the loops read one small array.
// Without extrapolation the margin is one voxel: the smaller array kept the extraction 10 %
// faster than one laid out for both (measured on the room at 2 cm).
template <int Margin>
struct Neighbourhood {
  static constexpr int kPad = kTsdfBlockSide + 1 + 2 * Margin;
  std::array<float, kPad * kPad * kPad> distance;
  static int at(int x, int y, int z) {
    return (x + Margin) + kPad * ((y + Margin) + kPad * (z + Margin));
  }
  float operator()(int x, int y, int z) const { return distance[at(x, y, z)]; }
};
constexpr int kExtrapolationMargin = 3;
using Extrapolated = Neighbourhood<kExtrapolationMargin>;

// Observed: not NaN.
bool isObserved(float d) {
  return d == d;
}
// Missing voxels are NaN; an unconfirmed one (TsdfConfig::confirm_depth_voxels: the mesh leaves
// it out) is the NaN with the sign bit set, so the extrapolation, the only reader that tells
// the two apart, does not fill it.
const float kMissing = std::numeric_limits<float>::quiet_NaN();
const float kUnconfirmed = -std::numeric_limits<float>::quiet_NaN();
bool isUnconfirmed(float d) {
  return !isObserved(d) && std::signbit(d);
}

// The extrapolation's bounds (TsdfConfig::mesh_extrapolate_voxels), in normalised distance D
// (one voxel = 1 / truncation_voxels).
struct Extrapolation {
  float near;   ///< |D1| of the observed voxel next to the missing one, at most
  float voxel;  ///< one voxel
};

/// Fills each missing voxel of the cube corners and their border (-1 .. 9) that is not
/// unconfirmed with 2 D1 - D2, D1 and D2 the two observed voxels before it along a lattice axis
/// (D1 the nearer), where
/// - D1 lies within `near` of the surface and D2 inside the band (|D2| < 1);
/// - along the surface, the two agree within a quarter voxel: the value keeps D1's sign and
///   continues the surface sideways (the edge the guard withheld). Measured: half a voxel let a
///   far floor's projective ramp, seen at grazing, run on one voxel under the floor;
/// - across it, they step by 0.9 to 1.05 voxels (a distance field's slope, one voxel per voxel
///   along the normal, within rounding and fusion's noise) and D1's four neighbours across the
///   axis lie within half a voxel of it (the surface faces the axis within 30 degrees): the
///   value changes sign, a surface just beyond the observed voxels. Other steps fill nothing
///   (under depth noise, D1 - D2 along a wall is noise, and doubling it flipped signs behind
///   walls). Measured: steps up to 1.2 continued the ray distance seen obliquely at the
///   frustum's edge (a plane's rim 0.7 mm off), and without the neighbour test a far floor's
///   projective ramp (D1 positive under the floor, its neighbours a voxel apart) was continued
///   2 cm under the floor;
/// - no observed neighbour of the opposite sign lies a whole band (|D| ~ 1) from any surface:
///   a crossing between the two would be a jump, not a surface.
/// Where several axes qualify, their mean, unless their signs differ (then it stays missing).
/// Reads only observed voxels, so a filled voxel is the same in every block that reads it.
void extrapolate(const Extrapolation& e, Extrapolated* n) {
  constexpr int kPad = Extrapolated::kPad;
  constexpr float kAlongSurface = 0.25f, kAcrossMin = 0.9f, kAcrossMax = 1.05f, kWholeBand = 0.99f;
  constexpr float kAcrossSideways = 0.5f;
  constexpr std::array<int, 6> kNeighbours = {1, -1, kPad, -kPad, kPad * kPad, -kPad * kPad};
  constexpr int kSide = kTsdfBlockSide + 3;  // -1 .. 9
  const Extrapolated& source = *n;
  // Applied after the scan, so every fill reads observed voxels only.
  std::array<int, kSide * kSide * kSide> fill_at;
  std::array<float, kSide * kSide * kSide> fill_value;
  int fills = 0;
  // Every fill reads a D1 within `near` of the surface: the voxels with none beside them (most
  // of the missing ones, deep behind surfaces) are passed over at the cost of six byte reads.
  std::array<std::uint8_t, kPad * kPad * kPad> near_surface;
  for (std::size_t k = 0; k < near_surface.size(); ++k) {
    near_surface[k] = std::abs(source.distance[k]) <= e.near;  // NaN: 0
  }
  for (int z = -1; z <= kTsdfBlockSide + 1; ++z) {
    for (int y = -1; y <= kTsdfBlockSide + 1; ++y) {
      for (int x = -1; x <= kTsdfBlockSide + 1; ++x) {
        const int i = Extrapolated::at(x, y, z);
        const float d0 = source.distance[i];
        if (isObserved(d0) || isUnconfirmed(d0)) continue;
        if (!(near_surface[i + 1] | near_surface[i - 1] | near_surface[i + kPad] |
              near_surface[i - kPad] | near_surface[i + kPad * kPad] |
              near_surface[i - kPad * kPad])) {
          continue;
        }
        float sum = 0.0f;
        int count = 0, negative = 0;
        for (const int q : kNeighbours) {
          const float d1 = source.distance[i + q];
          const float d2 = source.distance[i + 2 * q];
          const float step = std::abs(d1 - d2);  // NaN fails every comparison below
          if (!(std::abs(d1) <= e.near && std::abs(d2) < 1.0f)) continue;
          const float value = 2.0f * d1 - d2;
          const bool flips = (value < 0.0f) != (d1 < 0.0f);
          const bool along = !flips && step <= kAlongSurface * e.voxel;
          bool across = flips && step >= kAcrossMin * e.voxel && step <= kAcrossMax * e.voxel;
          for (const int l : kNeighbours) {
            if (!across) break;
            if (l == q || l == -q) continue;
            const float dl = source.distance[i + q + l];
            across = !(isObserved(dl) && std::abs(dl - d1) > kAcrossSideways * e.voxel);
          }
          if (!(along || across)) continue;
          sum += value;
          ++count;
          negative += value < 0.0f;
        }
        if (count == 0 || (negative != 0 && negative != count)) continue;
        const float value = sum / static_cast<float>(count);
        bool jump = false;
        for (const int q : kNeighbours) {
          const float d = source.distance[i + q];
          jump |= isObserved(d) && (d < 0.0f) != (value < 0.0f) && std::abs(d) > kWholeBand;
        }
        if (!jump) {
          fill_at[fills] = i;
          fill_value[fills++] = value;
        }
      }
    }
  }
  for (int k = 0; k < fills; ++k) n->distance[fill_at[k]] = fill_value[k];
}

/// Whether a cube of the block (corners at lattice 0 .. 8) holds both a negative and a
/// non-negative distance.
template <int Margin>
bool holdsSurface(const Neighbourhood<Margin>& n) {
  bool negative = false, non_negative = false;
  for (int z = 0; z <= kTsdfBlockSide; ++z) {
    for (int y = 0; y <= kTsdfBlockSide; ++y) {
      const float* row = &n.distance[Neighbourhood<Margin>::at(0, y, z)];
      for (int x = 0; x <= kTsdfBlockSide; ++x) {
        negative |= row[x] < 0.0f;
        non_negative |= row[x] >= 0.0f;  // NaN is neither
      }
    }
  }
  return negative && non_negative;
}

/// Whether extrapolation could give the block's corners a surface: they hold both signs, or a
/// voxel a fill may read as D1 (lattice -2 .. 10) lies within `near` of zero (without one
/// nothing is filled, and the block, seen only far in front of or behind surfaces, stays as
/// gathered).
bool mayHoldSurface(const Extrapolated& n, float near) {
  for (int z = -2; z <= kTsdfBlockSide + 2; ++z) {
    for (int y = -2; y <= kTsdfBlockSide + 2; ++y) {
      const float* row = &n.distance[Extrapolated::at(0, y, z)];
      bool any = false;
      for (int x = -2; x <= kTsdfBlockSide + 2; ++x) any |= std::abs(row[x]) <= near;
      if (any) return true;
    }
  }
  return holdsSurface(n);
}

/// Fills n; returns whether a cube of the block can hold a surface: its corners (lattice
/// 0 .. 8) hold both a negative and a non-negative distance, observed or extrapolated. About
/// 40 % of the blocks of a typical map hold none (free space in front of the surface, or
/// inside).
template <int Margin>
bool gather(const TsdfMap& map, const Eigen::Vector3i& block, Neighbourhood<Margin>* n) {
  const TsdfConfig& config = map.config();
  const auto min_weight = static_cast<float>(config.min_weight);
  std::array<const TsdfBlock*, 27> around{};
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        around[(dx + 1) + 3 * ((dy + 1) + 3 * (dz + 1))] =
            map.find(block + Eigen::Vector3i(dx, dy, dz));
      }
    }
  }
  const auto split = [](int a, int* offset, int* local) {
    *offset = a < 0 ? -1 : (a >= kTsdfBlockSide ? 1 : 0);
    *local = a - *offset * kTsdfBlockSide;
  };
  // An unconfirmed voxel has a negative weight.
  const auto gathered = [min_weight](const TsdfVoxel& v) {
    if constexpr (Margin == kExtrapolationMargin) {
      return v.weight > min_weight ? v.distance : (v.weight < 0.0f ? kUnconfirmed : kMissing);
    } else {
      return v.weight > min_weight ? v.distance : kMissing;
    }
  };
  const int first = -Margin, last = kTsdfBlockSide + Margin;
  // Row by row: the voxels from the block on the left, the centre block's eight (a plain loop
  // the compiler vectorises), those from the block on the right.
  for (int z = first; z <= last; ++z) {
    int oz, lz;
    split(z, &oz, &lz);
    for (int y = first; y <= last; ++y) {
      int oy, ly;
      split(y, &oy, &ly);
      const int row_blocks = 3 * ((oy + 1) + 3 * (oz + 1));
      float* out = &n->distance[Neighbourhood<Margin>::at(0, y, z)];
      const TsdfBlock* left = around[row_blocks];
      const TsdfBlock* right = around[row_blocks + 2];
      for (int x = first; x < 0; ++x) {
        out[x] = left == nullptr
                     ? kMissing
                     : gathered(left->voxels[TsdfBlock::linear(x + kTsdfBlockSide, ly, lz)]);
      }
      for (int x = kTsdfBlockSide; x <= last; ++x) {
        out[x] = right == nullptr
                     ? kMissing
                     : gathered(right->voxels[TsdfBlock::linear(x - kTsdfBlockSide, ly, lz)]);
      }
      const TsdfBlock* centre = around[row_blocks + 1];
      if (centre != nullptr) {
        const TsdfVoxel* v = &centre->voxels[TsdfBlock::linear(0, ly, lz)];
        for (int x = 0; x < kTsdfBlockSide; ++x) out[x] = gathered(v[x]);
      } else {
        std::fill(out, out + kTsdfBlockSide, kMissing);
      }
    }
  }
  if constexpr (Margin == kExtrapolationMargin) {
    const auto voxel = static_cast<float>(1.0 / config.truncation_voxels);  // in D
    const Extrapolation e{static_cast<float>(config.mesh_extrapolate_voxels) * voxel, voxel};
    if (!mayHoldSurface(*n, e.near)) return false;
    extrapolate(e, n);
  }
  return holdsSurface(*n);
}

bool hasZeroArea(const TriangleMesh& mesh, const std::array<std::uint32_t, 3>& ids) {
  const Eigen::Vector3f& a = mesh.vertices[ids[0]];
  return (mesh.vertices[ids[1]] - a).cross(mesh.vertices[ids[2]] - a).squaredNorm() == 0.0f;
}

// Exact position of a vertex as a hash key (+0 for -0, so the two zeros weld).
struct PositionKey {
  std::array<std::uint32_t, 3> bits;
  explicit PositionKey(const Eigen::Vector3f& p) {
    for (int a = 0; a < 3; ++a) {
      const float v = p(a) + 0.0f;
      std::memcpy(&bits[a], &v, sizeof(float));
    }
  }
  bool operator==(const PositionKey& o) const { return bits == o.bits; }
};
struct PositionKeyHash {
  std::size_t operator()(const PositionKey& k) const {
    return (std::size_t{k.bits[0]} * 73856093u) ^ (std::size_t{k.bits[1]} * 19349669u) ^
           (std::size_t{k.bits[2]} * 83492791u);
  }
};

}  // namespace

const std::vector<std::array<int, 3>>& marchingCubesCase(int inside_mask) {
  static const std::vector<std::vector<std::array<int, 3>>> table = [] {
    std::vector<std::vector<std::array<int, 3>>> t(256);
    for (int mask = 0; mask < 256; ++mask) t[mask] = deriveCase(mask);
    return t;
  }();
  return table[inside_mask & 255];
}

void TriangleMesh::append(const TriangleMesh& other) {
  const auto offset = static_cast<std::uint32_t>(vertices.size());
  vertices.insert(vertices.end(), other.vertices.begin(), other.vertices.end());
  normals.insert(normals.end(), other.normals.begin(), other.normals.end());
  // No exact reserve here: appending block after block, it would reallocate (and copy all) at
  // every call; push_back grows geometrically.
  for (const std::uint32_t i : other.triangles) triangles.push_back(i + offset);
}

std::string TriangleMesh::writePly(const std::string& path) const {
  std::ofstream out(path, std::ios::binary);
  if (!out) return "cannot open " + path + " for writing";
  writePly(out);
  out.flush();
  return out ? std::string() : "write to " + path + " failed";
}

void TriangleMesh::writePly(std::ostream& out) const {
  out << "ply\nformat binary_little_endian 1.0\ncomment downstream_perception TSDF mesh (m)\n"
      << "element vertex " << vertices.size()
      << "\nproperty float x\nproperty float y\nproperty float z\n"
      << "property float nx\nproperty float ny\nproperty float nz\n"
      << "element face " << triangleCount() << "\nproperty list uchar uint vertex_indices\n"
      << "end_header\n";
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    out.write(reinterpret_cast<const char*>(vertices[i].data()), 3 * sizeof(float));
    out.write(reinterpret_cast<const char*>(normals[i].data()), 3 * sizeof(float));
  }
  const unsigned char three = 3;
  for (std::size_t t = 0; t < triangleCount(); ++t) {
    out.write(reinterpret_cast<const char*>(&three), 1);
    out.write(reinterpret_cast<const char*>(&triangles[3 * t]), 3 * sizeof(std::uint32_t));
  }
}

namespace {

template <int Margin>
TriangleMesh extractBlockMeshWith(const TsdfMap& map, const Eigen::Vector3i& block) {
  using Gathered = Neighbourhood<Margin>;
  TriangleMesh mesh;
  Gathered n;
  // A block without a surface is done after the gather.
  if (!gather(map, block, &n)) return mesh;
  // Gradient of D (per voxel) by central differences, one-sided where a neighbour is missing.
  const auto gradient = [&](int x, int y, int z) {
    Eigen::Vector3f g = Eigen::Vector3f::Zero();
    const std::array<int, 3> p = {x, y, z};
    const float vc = n(x, y, z);
    for (int a = 0; a < 3; ++a) {
      std::array<int, 3> lo = p, hi = p;
      --lo[a];
      ++hi[a];
      const float vl = n(lo[0], lo[1], lo[2]);
      const float vh = n(hi[0], hi[1], hi[2]);
      if (isObserved(vl) && isObserved(vh)) {
        g(a) = 0.5f * (vh - vl);
      } else if (isObserved(vh) && isObserved(vc)) {
        g(a) = vh - vc;
      } else if (isObserved(vl) && isObserved(vc)) {
        g(a) = vc - vl;
      }
    }
    return g;
  };
  // Vertex of each lattice edge (lower corner's lattice index * 4 + axis) or lattice point
  // (index * 4 + kLatticePoint), shared within the block.
  constexpr int kLattice = kTsdfBlockSide + 1;
  constexpr int kLatticePoint = 3;
  std::array<std::int32_t, kLattice * kLattice * kLattice * 4> vertex_of_edge;
  vertex_of_edge.fill(-1);
  const double s = map.voxelSize();
  const Eigen::Vector3i origin = block * kTsdfBlockSide;
  for (int z = 0; z < kTsdfBlockSide; ++z) {
    for (int y = 0; y < kTsdfBlockSide; ++y) {
      // The row's eight cubes classified at once (a plain loop the compiler vectorises): the
      // inside mask of their corners (bit c: corner c negative), or 0 when a corner is
      // unobserved. Corner c of cube x lies in row (y + o[1], z + o[2]) at x + o[0].
      const float* r00 = &n.distance[Gathered::at(0, y, z)];
      const float* r10 = &n.distance[Gathered::at(0, y + 1, z)];
      const float* r01 = &n.distance[Gathered::at(0, y, z + 1)];
      const float* r11 = &n.distance[Gathered::at(0, y + 1, z + 1)];
      std::array<int, kTsdfBlockSide> masks;
      int any = 0;
      for (int x = 0; x < kTsdfBlockSide; ++x) {
        const float c[8] = {r00[x], r00[x + 1], r10[x + 1], r10[x],
                            r01[x], r01[x + 1], r11[x + 1], r11[x]};
        int mask = 0;
        bool complete = true;
        for (int k = 0; k < 8; ++k) {
          mask |= (c[k] < 0.0f) << k;
          complete &= isObserved(c[k]);
        }
        masks[x] = complete && mask != 255 ? mask : 0;
        any |= masks[x];
      }
      if (any == 0) continue;
      for (int x = 0; x < kTsdfBlockSide; ++x) {
        const int mask = masks[x];
        if (mask == 0) continue;
        std::array<float, 8> corner;
        for (int c = 0; c < 8; ++c) {
          const auto& o = kCubeCorners[c];
          corner[c] = n(x + o[0], y + o[1], z + o[2]);
        }
        for (const auto& tri : marchingCubesCase(mask)) {
          std::array<std::uint32_t, 3> ids;
          for (int k = 0; k < 3; ++k) {
            const int e = tri[k];
            const auto& ca = kCubeCorners[kCubeEdges[e][0]];
            const auto& cb = kCubeCorners[kCubeEdges[e][1]];
            // Canonical lattice edge: lower corner + axis.
            const std::array<int, 3> a = {x + ca[0], y + ca[1], z + ca[2]};
            const std::array<int, 3> b = {x + cb[0], y + cb[1], z + cb[2]};
            const bool a_low = a[0] + a[1] + a[2] < b[0] + b[1] + b[2];
            const std::array<int, 3>& low = a_low ? a : b;
            const std::array<int, 3>& high = a_low ? b : a;
            const int axis = a[0] != b[0] ? 0 : (a[1] != b[1] ? 1 : 2);
            // Interpolate from the lower lattice end, so the cubes (and blocks) sharing this
            // edge compute bit-identical vertices: no hairline cracks on block seams.
            const float d_low = corner[kCubeEdges[e][a_low ? 0 : 1]];
            const float d_high = corner[kCubeEdges[e][a_low ? 1 : 0]];
            const float t = d_low / (d_low - d_high);
            Eigen::Vector3f global((origin.x() + low[0]), (origin.y() + low[1]),
                                   (origin.z() + low[2]));
            global(axis) += t;
            // A crossing that lands on a lattice point (a surface through voxel centres) is
            // reached from up to six edges: key it by the point, so those edges share one
            // vertex and the triangles they pinch have equal ids (and are dropped).
            const bool on_low = global(axis) == static_cast<float>(origin(axis) + low[axis]);
            const bool on_high = global(axis) == static_cast<float>(origin(axis) + high[axis]);
            const std::array<int, 3>& point = on_high && !on_low ? high : low;
            const int kind = on_low || on_high ? kLatticePoint : axis;
            const int key = (point[0] + kLattice * (point[1] + kLattice * point[2])) * 4 + kind;
            if (vertex_of_edge[key] < 0) {
              vertex_of_edge[key] = static_cast<std::int32_t>(mesh.vertices.size());
              mesh.vertices.push_back(global * static_cast<float>(s));
              Eigen::Vector3f g = (1.0f - t) * gradient(low[0], low[1], low[2]) +
                                  t * gradient(high[0], high[1], high[2]);
              const float norm = g.norm();
              mesh.normals.push_back(norm > 0.0f ? (g / norm).eval() : Eigen::Vector3f::UnitZ());
            }
            ids[k] = static_cast<std::uint32_t>(vertex_of_edge[key]);
          }
          // Degenerate triangles (two corners pinched into one lattice point, or three
          // vertices on a line) are dropped: they have no area and no normal.
          if (ids[0] == ids[1] || ids[1] == ids[2] || ids[0] == ids[2] || hasZeroArea(mesh, ids)) {
            continue;
          }
          mesh.triangles.insert(mesh.triangles.end(), ids.begin(), ids.end());
        }
      }
    }
  }
  return mesh;
}

}  // namespace

TriangleMesh extractBlockMesh(const TsdfMap& map, const Eigen::Vector3i& block) {
  return map.config().mesh_extrapolate_voxels > 0.0
             ? extractBlockMeshWith<kExtrapolationMargin>(map, block)
             : extractBlockMeshWith<1>(map, block);
}

std::size_t TsdfMesher::update(const TsdfMap& map) {
  last_updated_.clear();
  const TsdfConfig& config = map.config();
  if (config.min_weight != meshed_min_weight_ ||
      config.mesh_extrapolate_voxels != meshed_extrapolate_voxels_) {
    meshes_.clear();  // every block is extracted again below
    meshed_min_weight_ = config.min_weight;
    meshed_extrapolate_voxels_ = config.mesh_extrapolate_voxels;
  }
  for (auto it = meshes_.begin(); it != meshes_.end();) {
    it = map.find(it->first) == nullptr ? meshes_.erase(it) : std::next(it);
  }
  tsl::robin_set<Eigen::Vector3i, BlockIndexHash> dirty;
  for (const auto& [key, block] : map.blocks()) {
    if (block->updated_stamp <= last_generation_ && meshes_.count(key) != 0) continue;
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const Eigen::Vector3i k = key + Eigen::Vector3i(dx, dy, dz);
          if (map.find(k) != nullptr) dirty.insert(k);
        }
      }
    }
  }
  for (const Eigen::Vector3i& key : dirty) {
    meshes_[key] = extractBlockMesh(map, key);
    last_updated_.push_back(key);
  }
  last_generation_ = map.generation();
  voxel_size_ = static_cast<float>(map.voxelSize());
  return dirty.size();
}

TriangleMesh TsdfMesher::combined() const {
  // Blocks share the vertices on their seams bit for bit (each is interpolated from the lower
  // lattice end, lattice coordinates scaled by the same float voxel size): welded by exact
  // position, every position is one vertex of the whole mesh.
  TriangleMesh all;
  std::size_t vertices = 0, indices = 0;
  for (const auto& [key, mesh] : meshes_) {
    vertices += mesh.vertices.size();
    indices += mesh.triangles.size();
  }
  all.vertices.reserve(vertices);
  all.normals.reserve(vertices);
  all.triangles.reserve(indices);
  tsl::robin_map<PositionKey, std::uint32_t, PositionKeyHash> id_of_position;
  id_of_position.reserve(vertices / 2);
  std::vector<std::uint32_t> id_of_local;
  for (const auto& [key, mesh] : meshes_) {
    // Only vertices on the block's faces can be shared; the others are appended unhashed.
    std::array<float, 3> lower_face, upper_face;
    for (int a = 0; a < 3; ++a) {
      lower_face[a] = static_cast<float>(key(a) * kTsdfBlockSide) * voxel_size_;
      upper_face[a] = static_cast<float>((key(a) + 1) * kTsdfBlockSide) * voxel_size_;
    }
    id_of_local.resize(mesh.vertices.size());
    for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
      const Eigen::Vector3f& p = mesh.vertices[i];
      auto id = static_cast<std::uint32_t>(all.vertices.size());
      bool seam = false;
      for (int a = 0; a < 3; ++a) seam |= p(a) == lower_face[a] || p(a) == upper_face[a];
      if (seam) {
        const auto [it, inserted] = id_of_position.try_emplace(PositionKey(p), id);
        id = it->second;
        if (!inserted) {
          id_of_local[i] = id;
          continue;
        }
      }
      all.vertices.push_back(p);
      all.normals.push_back(mesh.normals[i]);
      id_of_local[i] = id;
    }
    for (const std::uint32_t i : mesh.triangles) all.triangles.push_back(id_of_local[i]);
  }
  return all;
}

void TsdfMesher::clear() {
  meshes_.clear();
  last_generation_ = 0;
  last_updated_.clear();
}

}  // namespace downstream_perception
