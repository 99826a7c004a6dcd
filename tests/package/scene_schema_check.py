"""Keeps docs/scene.schema.json true (ctest scene_schema.ShippedScenesAndBrokenCorpus).

Every shipped scene (data/scenes/*.json) must validate. Every file of the broken corpus
(tests/data/scenes/broken/*.json) must be rejected by the schema, except the ones listed in
BEYOND_THE_SCHEMA, whose rule a JSON Schema cannot state (the loader's own messages, checked by
tests/csg/scene_file_test.cpp, stay the authority); those must be *accepted*, so the list
stays true when the schema learns a rule. A file that is not JSON at all is rejected by
definition. Run with Debian's /usr/bin/python3 and python3-jsonschema (scripts/bootstrap).

usage: scene_schema_check.py SOURCE_DIR
"""
import json
import pathlib
import sys

import jsonschema

# Broken files whose fault only the loader sees, and why.
BEYOND_THE_SCHEMA = {
    "camera_look_at.json": "look_at equal to position compares two values",
    "duplicate_key.json": "a duplicate key is gone once the JSON is parsed",
    "duplicate_nested_key.json": "a duplicate key is gone once the JSON is parsed",
    "camera_far.json": "the square of a vector's length overflowing is a norm, not a bound per value",
    "light_far.json": "the square of a vector's length overflowing is a norm, not a bound per value",
    "light_direction_underflow.json": "a length whose square underflows is a norm",
    "transform_bounds_overflow.json": "the bounds multiply the radius by the transform's scale",
    "transform_product_overflow.json": "a product of the transform steps",
    "transform_translate_overflow.json": "a sum of the transform steps",
    "transform_underflow.json": "the inverse of a step, not the step's own range",
    "grid_item.json": "a box's lower < upper compares two values",
    "grid_too_big.json": "the product of the counts",
    "mesh_corrupt.json": "the mesh file's content",
    "mesh_missing.json": "the mesh file's existence",
    "mesh_open_operand.json": "whether a mesh file is closed",
    "number_overflow.json": "1e999 parses as a number; the loader refuses the overflow",
    "ready_made_parameter.json": "outer_radius > inner_radius compares two values",
    "reference_cycle.json": "references between definitions",
    "self_reference.json": "references between definitions",
    "torus_radii.json": "minor_radius < major_radius compares two values",
    "unknown_definition.json": "references to definitions",
    "unknown_material.json": "references to materials",
    "nested_material.json": "references to materials",
    "light_rectangle_parallel_edges.json": "parallel edges compare two vectors",
    "array_copy_unknown_material_nested.json": "references to materials",
    "grid_ramp_nested_too_many.json": "the count of copies times the materials a ramp makes",
    "array_copy_unknown_material.json": "references to materials",
    "array_transform_product_overflow.json": "a product of the transform steps",
    "grid_copy_transform_overflow.json": "a power of the copy transform",
    "material_ramp_glass_and_paint.json": "the index of refraction of the named materials",
    "pile_hidden_between_samples.json": "how many objects' boxes overlap at one point",
    "reference_cycle_long_names.json": "references between definitions",
}


def main() -> int:
    root = pathlib.Path(sys.argv[1])
    schema = json.loads((root / "docs" / "scene.schema.json").read_text())
    jsonschema.Draft202012Validator.check_schema(schema)
    validator = jsonschema.Draft202012Validator(schema)
    failures = []

    shipped = sorted((root / "data" / "scenes").glob("*.json"))
    if not shipped:
        failures.append("no shipped scenes found in data/scenes")
    for path in shipped:
        for error in validator.iter_errors(json.loads(path.read_text())):
            pointer = "/" + "/".join(str(part) for part in error.absolute_path)
            failures.append(f"{path.name}: {pointer}: the schema rejects a shipped scene: "
                            f"{error.message}")

    broken = sorted((root / "tests" / "data" / "scenes" / "broken").glob("*.json"))
    if len(broken) < 40:
        failures.append(f"only {len(broken)} broken scenes found")
    names = {path.name for path in broken}
    for name in sorted(set(BEYOND_THE_SCHEMA) - names):
        failures.append(f"{name}: listed in BEYOND_THE_SCHEMA but not in the corpus")
    rejected = 0
    for path in broken:
        try:
            document = json.loads(path.read_text())
        except ValueError:
            rejected += 1  # not JSON: no schema can accept it
            continue
        errors = list(validator.iter_errors(document))
        if path.name in BEYOND_THE_SCHEMA:
            if errors:
                failures.append(f"{path.name}: the schema now rejects it ({errors[0].message}); "
                                "remove it from BEYOND_THE_SCHEMA")
        elif not errors:
            failures.append(f"{path.name}: the loader rejects it but the schema accepts it")
        else:
            rejected += 1

    for failure in failures:
        print(failure)
    print(f"{len(shipped)} shipped scenes valid; {rejected} of {len(broken)} broken scenes "
          f"rejected by the schema, {len(BEYOND_THE_SCHEMA)} beyond it")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
