// Probe sequences (iblkit.sequence/1, docs/formats.md): a manifest of probe images and the positions they
// were captured at, as Löw et al. 2009 [1] capture them with a mirror ball on a translation stage.
//
// [1] J. Löw, A. Ynnerman, P. Larsson, J. Unger. HDR light probe sequence resampling for realtime
//     incident light field rendering. SCCG 2009.
#pragma once
#include <string>
#include <vector>

#include "iblkit/core/vec.h"
#include "iblkit/ilf/ball.h"
#include "iblkit/sphere/mapping.h"

namespace ibl::ilf {

struct Box {
  Vec3 min, max;
  Vec3 size() const { return max - min; }
  Vec3 centre() const { return (min + max) * 0.5; }
  bool contains(Vec3 p, double slack = 0.0) const {
    return p.x >= min.x - slack && p.y >= min.y - slack && p.z >= min.z - slack && p.x <= max.x + slack &&
           p.y <= max.y + slack && p.z <= max.z + slack;
  }
};

struct ProbeEntry {
  std::string image;  // absolute (or manifest-relative resolved) path of the frame
  Vec3 position;      // capture position, world metres
  std::string depth;  // optional: path of a depth image beside the frame (lab captures; "" when none)
};

struct Sequence {
  std::string manifest;  // path the sequence was read from ("" when built in memory)
  sphere::MappingKind mapping = sphere::MappingKind::MirrorBall;  // mapping of every frame
  double dead_angle_deg = 0.0;                                    // mirror ball: unusable cone behind the ball
  BallOptics ball;                   // mirror ball: radius and camera distance (0, 0: a single viewpoint)
  Mat3 rotation = Mat3::identity();  // probe frame -> world
  Box volume;                        // capture volume (bounding box of the positions by default)
  bool volume_given = false;         // true when the manifest names the volume
  std::vector<ProbeEntry> probes;    // in capture order
  std::string scene;                 // optional: the lab scene the frames show ("" for real captures)
};

struct SequenceReadDesc {
  bool skip_bad = false;         // drop probes with bad fields (outside volume, duplicates) instead of failing
  double position_slack = 1e-6;  // metres a probe may sit outside the volume before it counts as outside
};

struct SequenceReport {
  int skipped = 0;                   // probes dropped because of skip_bad
  std::vector<std::string> reasons;  // one line per skipped probe
};

// Reads and validates a manifest. Errors name the probe index and the field: a manifest that does not
// parse, a wrong "format", an unknown mapping, a probe without "image" or "position", a non-finite
// position, a probe outside the volume, two probes at the same position. Image files are not opened
// here (the bucket sort reads each once).
Sequence read_sequence(const std::string& path, const SequenceReadDesc& desc = {}, SequenceReport* report = nullptr);

// Writes a manifest; image paths are written relative to the manifest's folder when they lie inside it.
void write_sequence(const std::string& path, const Sequence& seq);

}  // namespace ibl::ilf
