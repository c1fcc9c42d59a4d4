"""Validates the Kubernetes manifests in a folder (default: this script's) offline, against the
Kubernetes OpenAPI schema that the kubernetes-validate package ships, for each Kubernetes
version asked for. Strict: a field the schema does not know, a kind it has no schema for, a
duplicated key or a file that does not parse is an error. kustomization.yaml is no Kubernetes
resource and has no schema there: it must name only files of the folder, which are validated
like the others, and use only the fields these manifests need.

Exits 0 when every manifest passes, 1 otherwise. Run through validate.sh, which installs the
validator.
"""

import argparse
import pathlib
import sys

import kubernetes_validate
import yaml

KUSTOMIZATION = "kustomization.yaml"
KUSTOMIZATION_FIELDS = {"apiVersion", "kind", "resources", "images"}
KUSTOMIZATION_IMAGE_FIELDS = {"name", "newName", "newTag", "digest"}


class UniqueKeyLoader(yaml.SafeLoader):
    """PyYAML keeps the last of two equal keys without a word; Kubernetes' decoder refuses
    them, and so does this loader."""

    def construct_mapping(self, node, deep=False):
        seen = set()
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=deep)
            if key in seen:
                raise yaml.constructor.ConstructorError(
                    None, None, f"duplicate key {key!r}", key_node.start_mark
                )
            seen.add(key)
        return super().construct_mapping(node, deep=deep)


def documents(path):
    """The non-empty YAML documents of a file."""
    with open(path, encoding="utf-8") as f:
        return [doc for doc in yaml.load_all(f, Loader=UniqueKeyLoader) if doc is not None]


def resource_name(doc):
    metadata = doc.get("metadata") or {}
    return f"{doc.get('kind', '?')}/{metadata.get('name', '?')}"


def validate_resources(path, versions):
    """Errors of every document of one manifest file against every version's schema."""
    errors = []
    for index, doc in enumerate(documents(path)):
        if not isinstance(doc, dict) or "kind" not in doc or "apiVersion" not in doc:
            errors.append(f"document {index} is not a Kubernetes resource (kind, apiVersion)")
            continue
        for version in versions:
            try:
                kubernetes_validate.validate(doc, version, strict=True)
            except kubernetes_validate.ValidationError as e:
                where = ".".join(str(part) for part in e.path) or "(top level)"
                errors.append(f"{resource_name(doc)} (Kubernetes {version}): {where}: {e.message}")
            except (kubernetes_validate.SchemaNotFoundError, kubernetes_validate.InvalidSchemaError) as e:
                errors.append(f"{resource_name(doc)} (Kubernetes {version}): {e.message}")
    return errors


def check_kustomization(path):
    """Errors of kustomization.yaml: unknown fields, and resources that are not files here."""
    errors = []
    docs = documents(path)
    if len(docs) != 1 or not isinstance(docs[0], dict):
        return ["must hold exactly one mapping"]
    kustomization = docs[0]
    if kustomization.get("kind") != "Kustomization":
        errors.append("kind must be Kustomization")
    for field in sorted(set(kustomization) - KUSTOMIZATION_FIELDS):
        errors.append(f"unexpected field {field!r} (this check knows {sorted(KUSTOMIZATION_FIELDS)})")
    for resource in kustomization.get("resources", []):
        target = path.parent / str(resource)
        if target.parent != path.parent or not target.is_file():
            errors.append(f"resource {resource!r} is not a file of {path.parent}")
    for image in kustomization.get("images", []):
        if not isinstance(image, dict) or "name" not in image:
            errors.append(f"image {image!r} has no name")
            continue
        for field in sorted(set(image) - KUSTOMIZATION_IMAGE_FIELDS):
            errors.append(f"image {image['name']!r}: unexpected field {field!r}")
    return errors


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "folder",
        nargs="?",
        type=pathlib.Path,
        default=pathlib.Path(__file__).resolve().parent,
        help="folder of *.yaml manifests (default: the one this script is in)",
    )
    parser.add_argument(
        "--kubernetes-version",
        action="append",
        dest="versions",
        metavar="X.Y.Z",
        help="validate against this Kubernetes version's schema; repeatable "
        "(default: 1.31.0, the oldest these manifests support, and 1.37.0)",
    )
    args = parser.parse_args()
    versions = args.versions or ["1.31.0", "1.37.0"]

    files = sorted(args.folder.glob("*.yaml"))
    if not files:
        print(f"ERROR no *.yaml file in {args.folder}")
        return 1
    failed = 0
    for path in files:
        try:
            if path.name == KUSTOMIZATION:
                errors = check_kustomization(path)
            else:
                errors = validate_resources(path, versions)
        except yaml.YAMLError as e:
            errors = [f"not valid YAML: {e}"]
        for error in errors:
            print(f"ERROR {path.name}: {error}")
        if errors:
            failed += 1
        else:
            print(f"ok    {path.name}")
    print(f"{len(files) - failed} passed, {failed} failed (Kubernetes {', '.join(versions)}, strict)")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
