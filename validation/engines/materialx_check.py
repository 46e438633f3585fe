"""Check an exported MaterialX document with MaterialX's own library and colour management.

Usage: python materialx_check.py DOC.mtlx
Prints one JSON object: {"engine", "version", "valid", "message", "unknown_inputs",
"transformed": {input: [r, g, b]}}. `transformed` holds each color3 input after MaterialX's
default colour management to lin_rec709, read from the transform nodes its GLSL generator inserts
(the `ND_<space>_to_lin_rec709_color3` implementation applied to the input's value).
"""

import json
import sys

import MaterialX as mx
import MaterialX.PyMaterialXGenShader as mx_gen_shader
import MaterialX.PyMaterialXGenGlsl as mx_gen_glsl


def main() -> None:
    path = sys.argv[1]
    lib = mx.createDocument()
    mx.loadLibraries(mx.getDefaultDataLibraryFolders(), mx.getDefaultDataSearchPath(), lib)
    doc = mx.createDocument()
    mx.readFromXmlFile(doc, path)
    doc.importLibrary(lib)
    valid, message = doc.validate()
    unknown = []
    space = doc.getColorSpace()
    values = {}
    for node in doc.getNodes():
        nodedef = node.getNodeDef()
        for inp in node.getInputs():
            spec = nodedef.getActiveInput(inp.getName()) if nodedef else None
            if spec is None or spec.getType() != inp.getType():
                unknown.append(inp.getName())
            if inp.getType() == "color3" and inp.getValue() is not None:
                values[inp.getName()] = list(inp.getValue().asTuple())
    # MaterialX's default CMS: which inputs it would transform, and with which matrix.
    gen = mx_gen_glsl.GlslShaderGenerator.create()
    context = mx_gen_shader.GenContext(gen)
    context.registerSourceCodeSearchPath(mx.getDefaultDataSearchPath())
    cms = mx_gen_shader.DefaultColorManagementSystem.create(gen.getTarget())
    cms.loadLibrary(lib)
    gen.setColorManagementSystem(cms)
    context.getOptions().targetColorSpaceOverride = "lin_rec709"
    shader_node = doc.getNodes()[0]
    shader = gen.generate("skin", shader_node, context)
    code = shader.getSourceCode(mx_gen_shader.PIXEL_STAGE)
    transform = f"{space}_to_lin_rec709"
    matrix = None
    impl = lib.getNodeDef(f"ND_{transform}_color3")
    if space != "lin_rec709" and impl is not None:
        graph = impl.getImplementation()
        for node in graph.getNodes() if graph is not None and graph.isA(mx.NodeGraph) else []:
            if node.getCategory() == "constant" and node.getType() == "matrix33":
                m = [float(v) for v in node.getInputValue("value").split(",")] if isinstance(
                    node.getInputValue("value"), str) else [
                    float(v) for v in node.getInput("value").getValueString().split(",")]
                matrix = [m[3 * i:3 * i + 3] for i in range(3)]
    out = {}
    for name, v in values.items():
        if matrix is None:
            out[name] = v
        else:
            # MaterialX multiplies the colour as a row vector: c' = c M.
            out[name] = [sum(v[i] * matrix[i][j] for i in range(3)) for j in range(3)]
    print(json.dumps({
        "engine": "materialx",
        "version": mx.__version__,
        "colorspace": space,
        "valid": bool(valid),
        "message": message,
        "unknown_inputs": unknown,
        "cm_in_shader": transform in code,
        "matrix": matrix,
        "transformed": out,
    }))


if __name__ == "__main__":
    main()
