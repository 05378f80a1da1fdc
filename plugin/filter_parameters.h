#ifndef FILTER_PARAMETERS_H
#define FILTER_PARAMETERS_H

// The labels of the filter's enum parameters, in the order of their values: shared by the
// parameter list (filter_parameters.cpp) and the log (filter_implicit_boundaries.cpp).

#include <QStringList>

namespace ib_plugin {

// The first two match ib::Reconstruction::NormalSource; the third is Estimate with the viewpoint.
extern const QStringList kNormalSources;
constexpr int kNormalsFacingViewpoint = 2;
// Order matches ib::Reconstruction::Occupancy.
extern const QStringList kOccupancies;
// Order matches ib::Reconstruction::Implicit.
extern const QStringList kImplicits;
// Order matches ib::GatedMarchingCubes::Extraction.
extern const QStringList kExtractions;

} // namespace ib_plugin

#endif
