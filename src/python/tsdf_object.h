// The Python Tsdf object (bind_tsdf.cpp, bind_esdf.cpp): the map with its integrator, its
// incremental mesher and, made on first use, its ESDF.
#pragma once

#include <memory>

#include "downstream_perception/core/tsdf/esdf.h"
#include "downstream_perception/core/tsdf/marching_cubes.h"
#include "downstream_perception/core/tsdf/tsdf_integrator.h"
#include "downstream_perception/core/tsdf/tsdf_map.h"

namespace downstream_perception {
namespace python {

struct Tsdf {
  explicit Tsdf(const TsdfConfig& config) : map(config) {}
  TsdfMap map;
  DepthIntegrator integrator;
  TsdfMesher mesher;
  /// Made with EsdfConfig's defaults on first use (set_esdf_config replaces it): a default that
  /// does not suit this map's voxel size raises then, not when the Tsdf is made.
  std::unique_ptr<Esdf> esdf;
};

}  // namespace python
}  // namespace downstream_perception
