// ilf::write_vdb: the OpenVDB writer when this build has OpenVDB (ilf/vdb_export.cpp, in the "vdb"
// plugin for the iblkit command), a clear error otherwise.
#include "iblkit/core/error.h"
#include "iblkit/ilf/shgrid.h"
#include "iblkit/ilf/vdb_writer.h"

namespace ibl::ilf {

namespace detail {
constinit plugin::Provided<VdbWriter> vdb_writer{"vdb", "OpenVDB writer"};
}  // namespace detail

#ifdef IBLKIT_HAVE_OPENVDB
bool have_vdb() { return true; }
#else
bool have_vdb() { return false; }
#endif

void write_vdb(const std::string& path, const SHGrid& g) {
  if (!have_vdb())
    fail(ErrorKind::Unsupported, "{}: this build has no OpenVDB (configure with OpenVDB found to write .vdb grids)",
         path);
  detail::vdb_writer.get().write(path, g);
}

}  // namespace ibl::ilf
