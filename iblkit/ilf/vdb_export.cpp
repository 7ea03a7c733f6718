// OpenVDB export of an SH grid (`ilf build --vdb`), for Houdini and Blender users: one Vec3f grid per
// coefficient, voxel (i, j, k) = grid point (i, j, k), a scale+translate transform to world metres.
// Built only with OpenVDB, into the "vdb" plugin for the iblkit command (ilf/vdb.cpp calls it).
#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>

#include "iblkit/core/atomic_file.h"
#include "iblkit/core/error.h"
#include "iblkit/ilf/shgrid.h"
#include "iblkit/ilf/vdb_writer.h"

namespace ibl::ilf::vdb_file {

namespace {

void write_vdb(const std::string& path, const SHGrid& g) {
  openvdb::initialize();
  const auto& gd = g.grid();
  Vec3 sp = gd.spacing();
  int K = g.coeff_count();
  openvdb::GridPtrVec grids;
  // Index (i, j, k) -> world min + spacing·(i, j, k): a row-vector matrix, translation in the last row.
  openvdb::math::Mat4d m = openvdb::math::Mat4d::identity();
  m.setToScale(openvdb::Vec3d(sp.x, sp.y, sp.z));
  m.setTranslation(openvdb::Vec3d(gd.volume.min.x, gd.volume.min.y, gd.volume.min.z));
  auto xf = openvdb::math::Transform::createLinearTransform(m);
  for (int l = 0, k = 0; l < g.bands(); ++l)
    for (int m = -l; m <= l; ++m, ++k) {
      auto grid = openvdb::Vec3fGrid::create(openvdb::Vec3f(0.0f));
      grid->setName(fmt::format("sh_l{}_m{}", l, m));
      grid->setTransform(xf->copy());
      grid->setGridClass(openvdb::GRID_UNKNOWN);
      auto acc = grid->getAccessor();
      for (int z = 0; z < gd.nz; ++z)
        for (int y = 0; y < gd.ny; ++y)
          for (int x = 0; x < gd.nx; ++x) {
            const float* v = g.at(x, y, z) + 3 * k;
            acc.setValue(openvdb::Coord(x, y, z), openvdb::Vec3f(v[0], v[1], v[2]));
          }
      grid->insertMeta("iblkit_l", openvdb::Int32Metadata(l));
      grid->insertMeta("iblkit_m", openvdb::Int32Metadata(m));
      grids.push_back(grid);
    }
  openvdb::MetaMap meta;
  meta.insertMeta("iblkit_format", openvdb::StringMetadata("iblkit.shgrid/1"));
  meta.insertMeta("iblkit_bands", openvdb::Int32Metadata(g.bands()));
  meta.insertMeta("iblkit_coefficients", openvdb::Int32Metadata(K));
  meta.insertMeta("iblkit_min",
                  openvdb::Vec3DMetadata(openvdb::Vec3d(gd.volume.min.x, gd.volume.min.y, gd.volume.min.z)));
  meta.insertMeta("iblkit_max",
                  openvdb::Vec3DMetadata(openvdb::Vec3d(gd.volume.max.x, gd.volume.max.y, gd.volume.max.z)));
  meta.insertMeta("iblkit_resolution", openvdb::Vec3IMetadata(openvdb::Vec3i(gd.nx, gd.ny, gd.nz)));
  meta.insertMeta("iblkit_sh_convention",
                  openvdb::StringMetadata("real orthonormal, no Condon-Shortley phase, k = l(l+1)+m"));
  AtomicFile out(path);
  try {
    openvdb::io::File file(out.temp_path());
    file.write(grids, meta);
    file.close();
  } catch (const openvdb::Exception& e) {
    fail(ErrorKind::Io, "{}: cannot write OpenVDB file ({})", path, e.what());
  }
  out.commit();
}

const detail::VdbWriter kWriter{write_vdb};
[[maybe_unused]] const bool kProvided = (detail::vdb_writer.provide(&kWriter), true);

}  // namespace

}  // namespace ibl::ilf::vdb_file
