"""The definitions the tests of tests/lsp/ open: the arm of specs/examples, edited."""

HEAD = """\
model:
  robotname: arm
  modelname: arm-model
  input_models:
    arm:
      basefile: arm.urdf
  assemble:
    model: arm
"""
EXPORT = """\
  export_config:
    - type: urdf
      mesh_format: stl
"""
