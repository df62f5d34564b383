"""Give a document object made by objects/ its view provider: the GUI owns the screen, so
objects/ never imports gui/. Commands call `show` on what they create; GUI macros do the same:

    from freecad_conformal.objects.job_feature import create_job
    from freecad_conformal.gui.views import show
    show(create_job(doc, body))
"""
from __future__ import annotations


def show(obj):
    """Attach the view provider that matches the object's proxy; returns the object.
    Objects this workbench does not know are left as FreeCAD draws them."""
    from freecad_conformal.gui import view_axis, view_providers
    from freecad_conformal.objects.analysis_feature import AnalysisFeature, DecompositionFeature
    from freecad_conformal.objects.feature_object import ConformalFeature
    from freecad_conformal.objects.post_feature import PostFeature, VerifyFeature
    from freecad_conformal.objects.sections_feature import SectionsFeature
    from freecad_conformal.objects.toolpath_feature import ToolpathFeature

    proxy = getattr(obj, "Proxy", None)
    vobj = obj.ViewObject
    if vobj is None:
        return obj
    if isinstance(proxy, SectionsFeature):
        view_providers.ViewProviderSections(vobj)
    elif isinstance(proxy, ToolpathFeature):
        view_providers.ViewProviderToolpath(vobj)
        if isinstance(proxy, ConformalFeature):
            vobj.ColourBy = "Kind"
    elif isinstance(proxy, DecompositionFeature):
        view_axis.ViewProviderDecomposition(vobj)
        obj.Source.ViewObject.Visibility = False   # the sub-parts replace the body on screen
    elif isinstance(proxy, AnalysisFeature):
        view_axis.ViewProviderAnalysis(vobj)
    elif isinstance(proxy, (PostFeature, VerifyFeature)):
        view_providers.ViewProviderProgram(vobj)
    return obj
