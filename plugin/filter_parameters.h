#ifndef FILTER_PARAMETERS_H
#define FILTER_PARAMETERS_H

// The labels of the filter's enum parameters, in the order of their values: shared by the
// parameter list (filter_parameters.cpp) and the log (filter_implicit_boundaries.cpp); the
// tile parameters read into the core's type.

#include "core/tiling.h"

#include <QStringList>

class RichParameterList;

namespace ib_plugin {

// Each list's index i is the label of the core enum value i (checked at compile time in
// filter_parameters.cpp): ib::Reconstruction::NormalSource (then Estimate with the viewpoint),
// Occupancy, Implicit, and ib::GatedMarchingCubes::Extraction.
extern const QStringList kNormalSources;
constexpr int kNormalsFacingViewpoint = 2;
extern const QStringList kOccupancies;
extern const QStringList kImplicits;
extern const QStringList kExtractions;

/// The tile parameters (lattice_cell, lattice_origin, ..., block_max) as the core's Tile.
ib::Tile tileParameters(const RichParameterList& par);

} // namespace ib_plugin

#endif
