#ifndef FILTER_IMPLICIT_BOUNDARIES_H
#define FILTER_IMPLICIT_BOUNDARIES_H

// MeshLab glue of "Implicit reconstruction with boundaries": the plugin, its result dictionary
// and log; the parameters are in filter_parameters.cpp, reading the layers in input_layers.cpp.
// The algorithm lives in core/ (no Qt, no MeshLab).

#include <common/plugins/interfaces/filter_plugin.h>

class FilterImplicitBoundariesPlugin : public QObject, public FilterPlugin
{
	Q_OBJECT
	MESHLAB_PLUGIN_IID_EXPORTER(FILTER_PLUGIN_IID)
	Q_INTERFACES(FilterPlugin)

public:
	enum { IMPLICIT_RECONSTRUCTION_WITH_BOUNDARIES };

	FilterImplicitBoundariesPlugin();

	QString pluginName() const;
	QString filterName(ActionIDType filter) const;
	QString pythonFilterName(ActionIDType filter) const;
	QString filterInfo(ActionIDType filter) const;
	FilterClass getClass(const QAction*) const;
	FilterArity filterArity(const QAction*) const;
	int getPreConditions(const QAction*) const;
	int postCondition(const QAction*) const;
	RichParameterList initParameterList(const QAction*, const MeshDocument& md);
	std::map<std::string, QVariant> applyFilter(
		const QAction*           action,
		const RichParameterList& parameters,
		MeshDocument&            md,
		unsigned int&            postConditionMask,
		vcg::CallBackPos*        cb);

private:
	RichParameterList reconstructionParameters(const MeshDocument& md) const;
	static void addTileParameters(RichParameterList& par);
	std::map<std::string, QVariant> reconstructWithBoundaries(
		MeshDocument& md, const RichParameterList& par, vcg::CallBackPos* cb);
};

#endif
