"""bpy glue: properties, panels, operators, export of the scene to numpy."""
