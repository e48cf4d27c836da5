"""Pure numpy/scipy maths of SG-PRT. Nothing under this package imports bpy."""
