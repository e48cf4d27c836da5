"""A material as the engine exports it, with the warnings the export gave (the Blender-tier tests of what a
material's settings render as)."""


def export_with_warnings(material):
    """(export.MaterialParams, [warning text]) of one material."""
    from sg_prt_addon.blender import export

    warnings = export.collect_warnings([])
    try:
        return export.export_material(material), warnings
    finally:
        export.collect_warnings(None)
