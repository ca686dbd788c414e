"""Mission files → validated MissionSpecs, with every error at file:line.

Validation happens in one pass over the YAML: each node's kind is looked up
(composite, decorator, skill from the registry, behaviour from behaviors/),
its body validated by that kind's pydantic model, and skill parameters
checked against the robot and the world. The first problem found is raised
as a UserError naming the place and what would be valid.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, get_args

from pydantic import BaseModel, ValidationError

from bt_humanoid.errors import UserError, did_you_mean
from bt_humanoid.mission.behaviors import BehaviorLibrary, substitute
from bt_humanoid.mission.schema import (
    COMPOSITES,
    CONDITION_KINDS,
    LOADER_BODIES,
    NODE_EXTRAS,
    MissionHeader,
    RecoverySettings,
    SuccessCondition,
    structural_kinds,
)
from bt_humanoid.mission.spec import MissionSpec, NodeSpec
from bt_humanoid.paths import behaviors_dir
from bt_humanoid.sim.assembly import joint_ranges
from bt_humanoid.sim.robot_config import load_robot_config
from bt_humanoid.sim.scene_config import SceneConfig, load_scene
from bt_humanoid.sim.world_config import WorldConfig, load_world_config
from bt_humanoid.skills import REGISTRY
from bt_humanoid.skills.context import CheckContext
from bt_humanoid.skills.params import is_reference
from bt_humanoid.yaml_source import YamlPath, YamlSource, display_path, read_yaml

MAX_SUBTREE_DEPTH = 32


def validate_params(model: type[BaseModel], raw: Any, source: YamlSource, path: YamlPath, prefix: str) -> BaseModel:
    """Validate a skill's parameters; ``"$key"`` blackboard references are checked when the leaf starts."""
    if raw is None:
        raw = {}
    if not isinstance(raw, dict):
        raise UserError(f"{prefix}parameters must be a mapping, got {type(raw).__name__}", where=source.where(path))
    # a reference is checked when the leaf starts, but only for a parameter the skill has: an unknown name is wrong now
    references = {key for key, value in raw.items() if is_reference(value) and key in model.model_fields}
    concrete = {key: value for key, value in raw.items() if key not in references}
    try:
        return model.model_validate(concrete)
    except ValidationError as error:
        # a field given by reference, and checks across fields (no location) while one is, wait for the leaf to start
        remaining = [e for e in error.errors() if not (e["loc"][0] in references if e["loc"] else references)]
        if not remaining:
            return model.model_construct(**concrete)
        first_only = ValidationError.from_exception_data(error.title, [remaining[0]])  # type: ignore[list-item]
        raise source.invalid(first_only, path, prefix) from None


MAX_TREE_DEPTH = 64  # levels of nodes: far beyond any real mission, well inside Python's recursion limit


class MissionLoader:
    """Loads missions against the skill registry, a behaviour library and the named robot and world."""

    def __init__(
        self,
        library: BehaviorLibrary | None = None,
        check_world: bool = True,
        subtree_roots: Sequence[Path] | None = None,
        scene: str | SceneConfig | None = None,
        robot: str | None = None,
    ) -> None:
        self.library = library or BehaviorLibrary()
        # the robot given on the command line (--robot), over the mission's: the mission is checked against it
        self.robot = robot
        # the scene given on the command line (a name, or a path from the working directory), over the mission's
        self.scene = scene
        # False when checking a behaviour on its own: its arguments are placeholders then
        self.check_world = check_world
        # None: a subtree file is any file, relative to the one calling it (a person's own mission files).
        # Folders: subtree files must lie inside one of them (a planner's missions: only the project's behaviours).
        self.subtree_roots = None if subtree_roots is None else [Path(root).resolve() for root in subtree_roots]

    @classmethod
    def for_plans(cls) -> MissionLoader:
        """The loader for missions a planner wrote: subtree files only from the project's behaviors/ folder."""
        return cls(subtree_roots=[behaviors_dir()])

    # --- entry points ------------------------------------------------------------

    def load_file(self, file: Path) -> MissionSpec:
        return self.load_source(read_yaml(Path(file)))

    def load_text(self, text: str, name: str = "<mission>") -> MissionSpec:
        return self.load_source(read_yaml(Path(name), text))

    def load_data(self, data: dict[str, Any], name: str = "<plan>") -> MissionSpec:
        """A mission given as data (a planner's output): errors name the plan step instead of a line."""
        return self.load_source(YamlSource(Path(name), data))

    def load_source(self, source: YamlSource) -> MissionSpec:
        data = source.data
        if not isinstance(data, dict):
            raise UserError("a mission is a mapping with mission, tree and optional sections", where=source.where(()))
        if "tree" not in data:
            raise UserError("missing required section 'tree'", where=source.where(()))
        header_data = {k: v for k, v in data.items() if k != "tree"}
        self._check_condition_kinds(header_data.get("success"), source)
        try:
            header = MissionHeader.model_validate(header_data)
        except ValidationError as error:
            raise source.invalid(error, ()) from None
        if self.robot is not None:
            header = header.model_copy(update={"robot": self.robot})
        robot = _config_at(load_robot_config, header.robot, source, "robot")
        world = _config_at(load_world_config, header.world, source, "world")
        self.checks = CheckContext(robot, world, joint_ranges(robot))
        scene = self._scene(header, world, source)
        self._check_success(header, source, scene)
        alternatives = self._skill_recovery(header, source)
        tree = self._node(data["tree"], source, ("tree",), "tree", stack=())
        return MissionSpec(header, tree, self.checks, source.file, alternatives, scene)

    def _scene(self, header: MissionHeader, world: WorldConfig, source: YamlSource) -> SceneConfig | None:
        """The scene the mission starts from: the command line's, else the mission's, else the world's own."""
        if isinstance(self.scene, SceneConfig):
            return self.scene
        if self.scene is not None:
            return load_scene(world, self.scene, named_at="--scene")
        if header.scene is not None:
            base = None if source.file.name.startswith("<") else source.file.parent
            return load_scene(world, header.scene, base, named_at=source.where(("scene",)))
        if world.scene is not None and self.check_world:
            return load_scene(world, world.scene, named_at=f"worlds/{world.folder.name}/world.yaml")
        return None

    # --- nodes ----------------------------------------------------------------------

    def _node(self, raw: Any, source: YamlSource, ypath: YamlPath, path: str, stack: tuple[str, ...]) -> NodeSpec:
        where = source.where(ypath)
        if len(ypath) > 2 * MAX_TREE_DEPTH:  # each level adds a kind key and an index or a parameter name
            raise UserError(f"the tree is nested more than {MAX_TREE_DEPTH} levels deep", where=where)
        if not isinstance(raw, dict) or not raw:
            raise UserError(
                f"a tree node is a mapping with one kind key (a composite, decorator, skill or behaviour), "
                f"got {type(raw).__name__ if raw is not None else 'nothing'}",
                where=where,
            )
        kinds = [key for key in raw if key not in NODE_EXTRAS]
        if len(kinds) != 1:
            found = ", ".join(map(str, kinds)) or "none"
            raise UserError(
                f"a tree node needs exactly one kind key, found: {found} (besides optional {', '.join(NODE_EXTRAS)})",
                where=where,
            )
        kind = str(kinds[0])
        body = raw[kind]
        bpath = (*ypath, kind)
        node_path = kind if path == "tree" else (path + kind if path.endswith(">") else f"{path}.{kind}")
        name = raw.get("name")
        if name is not None and not isinstance(name, str):
            raise UserError("name must be a string", where=source.where((*ypath, "name")))
        recovery, alternative = None, None
        if "recovery" in raw:
            recovery, alternative = self._recovery(raw["recovery"], source, (*ypath, "recovery"), node_path, stack)

        def spec(**kw: Any) -> NodeSpec:
            return NodeSpec(
                kind=kind,
                path=node_path,
                where=source.where(bpath),
                name=name,
                recovery=recovery,
                alternative=alternative,
                **kw,
            )

        if kind in COMPOSITES:
            if not isinstance(body, list) or not body:
                raise UserError(f"{kind} takes a non-empty list of child nodes", where=source.where(bpath))
            children = [
                self._node(child, source, (*bpath, i), f"{node_path}[{i}]", stack) for i, child in enumerate(body)
            ]
            return spec(category="composite", children=children)
        if kind in LOADER_BODIES:
            return self._decorator(kind, body, source, bpath, node_path, stack, spec)
        if kind in REGISTRY:
            return self._skill(kind, body, source, bpath, node_path, spec)
        if kind in self.library.behaviors:
            return self._behavior_call(kind, body, source, bpath, node_path, stack, spec)
        options = [*structural_kinds(), *REGISTRY, *self.library.behaviors]
        raise UserError(
            f"unknown skill or node kind '{kind}'", where=source.where(bpath), hint=did_you_mean(kind, options)
        )

    def _recovery(
        self, raw: Any, source: YamlSource, ypath: YamlPath, node_path: str, stack: tuple[str, ...]
    ) -> tuple[RecoverySettings, NodeSpec | None]:
        """A recovery mapping, and its alternative node loaded like any other (paths ``….alternative.…``)."""
        try:
            recovery = RecoverySettings.model_validate(raw)
        except ValidationError as error:
            raise source.invalid(error, ypath) from None
        alternative = None
        if recovery.alternative is not None:
            alternative = self._node(
                recovery.alternative, source, (*ypath, "alternative"), f"{node_path}.alternative", stack
            )
        return recovery, alternative

    def _decorator(self, kind, body, source, bpath, node_path, stack, spec) -> NodeSpec:
        model = LOADER_BODIES[kind]
        if not isinstance(body, dict):
            raise UserError(f"{kind} takes a mapping with {', '.join(model.model_fields)}", where=source.where(bpath))
        try:
            settings = model.model_validate(body)
        except ValidationError as error:
            raise source.invalid(error, bpath, prefix=f"{kind}: ") from None
        if kind == "subtree":
            return self._subtree_file(settings, source, bpath, node_path, stack, spec)
        children = []
        if kind == "parallel":
            children = [
                self._node(child, source, (*bpath, "children", i), f"{node_path}[{i}]", stack)
                for i, child in enumerate(body["children"])
            ]
        else:
            if kind == "guard":
                children.append(
                    self._node(body["condition"], source, (*bpath, "condition"), f"{node_path}.condition", stack)
                )
            children.append(self._node(body["child"], source, (*bpath, "child"), node_path, stack))
        return spec(category="decorator", settings=settings, children=children)

    def _skill(self, kind, body, source, bpath, node_path, spec) -> NodeSpec:
        info = REGISTRY[kind]
        params = validate_params(info.params, body, source, bpath, prefix=f"{kind}: ")
        raw = dict(body or {})
        if self.check_world and not any(is_reference(v) for v in raw.values()):
            for parameter, message in info.behaviour.check(params, self.checks):
                raise UserError(f"{kind}: {message}", where=source.where((*bpath, parameter)))
        return spec(category="skill", settings=params, raw=raw)

    def _behavior_call(self, kind, body, source, bpath, node_path, stack, spec) -> NodeSpec:
        behavior = self.library.behaviors[kind]
        args_model = behavior.args_model
        try:
            args = args_model.model_validate(body or {})
        except ValidationError as error:
            raise source.invalid(error, bpath, prefix=f"{kind}: ") from None
        return self._expand(kind, behavior.source, args.model_dump(), source, bpath, node_path, stack, spec)

    def _subtree_file(self, settings, source, bpath, node_path, stack, spec) -> NodeSpec:
        if self.subtree_roots is None:
            file = (source.file.parent / settings.file).resolve()
            if not file.is_file():
                raise UserError(
                    f"subtree file not found: {display_path(file)}",
                    where=source.where((*bpath, "file")),
                    hint="paths are relative to the file that calls them",
                )
        else:
            file = self._confined_subtree(settings.file, source, bpath)
        from bt_humanoid.mission.behaviors import load_behavior

        behavior = load_behavior(file)
        try:
            args = behavior.args_model.model_validate(settings.args)
        except ValidationError as error:
            raise source.invalid(error, (*bpath, "args"), prefix=f"subtree {behavior.name}: ") from None
        return self._expand(behavior.name, behavior.source, args.model_dump(), source, bpath, node_path, stack, spec)

    def _confined_subtree(self, name: str, source: YamlSource, bpath: YamlPath) -> Path:
        """A subtree file inside the allowed folders: relative to the calling file when that lies inside one
        (a behaviour calling another), else to the first folder (a plan names ``pick.yaml``)."""
        roots = self.subtree_roots or []
        caller = source.file.resolve().parent  # a plan's "file" (<plan>) is no file: its folder is no base
        inside = not source.file.name.startswith("<") and any(caller.is_relative_to(root) for root in roots)
        base = caller if inside else roots[0]
        file = (base / name).resolve()  # symbolic links resolved: a link out of the folder is outside it
        if any(file.is_relative_to(root) for root in roots) and file.is_file():
            return file
        valid = sorted(str(path.relative_to(roots[0])) for path in roots[0].rglob("*.yaml"))
        valid += sorted(display_path(path) for root in roots[1:] for path in root.rglob("*.yaml"))
        folders = " or ".join(f"{display_path(root)}/" for root in roots)
        if any(file.is_relative_to(root) for root in roots):
            problem = f"not found in {folders}"
        else:
            problem = f"outside {folders}: a planned mission may call only the project's behaviours"
        raise UserError(
            f"subtree file '{name}' is {problem}",
            where=source.where((*bpath, "file")),
            hint=f"valid: {', '.join(valid)}; or call a behaviour by name, e.g. pick: {{object: red cube}}",
        )

    def _expand(self, name, behavior_source, args, call_source, bpath, node_path, stack, spec) -> NodeSpec:
        if name in stack:
            chain = " → ".join([*stack, name])
            raise UserError(f"recursive subtree: {chain}", where=call_source.where(bpath))
        if len(stack) >= MAX_SUBTREE_DEPTH:
            raise UserError(f"subtrees nested deeper than {MAX_SUBTREE_DEPTH}", where=call_source.where(bpath))
        tree = substitute(behavior_source.data["tree"], args, behavior_source, ("tree",))
        expanded = YamlSource(behavior_source.file, {"tree": tree}, behavior_source.lines)
        try:
            root = self._node(tree, expanded, ("tree",), f"{node_path}>", (*stack, name))
        except UserError as error:  # e.g. an argument refused where the behaviour passes it on: name the call too
            raise UserError(f"in behaviour {name}: {error}", where=call_source.where(bpath)) from None
        return spec(category="behavior", children=[root])

    # --- header checks against the world -------------------------------------------

    def _check_condition_kinds(self, success: Any, source: YamlSource) -> None:
        """Each success condition names one known kind; its fields are then checked by that kind's model."""
        if success is None:
            return
        if not isinstance(success, list):
            raise UserError("success: a list of conditions", where=source.where(("success",)))
        for i, condition in enumerate(success):
            kinds = list(condition) if isinstance(condition, dict) else []
            if len(kinds) != 1 or kinds[0] not in CONDITION_KINDS:
                shown = ", ".join(map(str, kinds)) or repr(condition)
                raise UserError(
                    f"success: unknown condition '{shown}'",
                    where=source.where(("success", i)),
                    hint=f"valid: {', '.join(CONDITION_KINDS)}",
                )
            model = next(m for m in get_args(SuccessCondition) if kinds[0] in m.model_fields)
            try:
                model.model_validate(condition)
            except ValidationError as error:
                raise source.invalid(error, ("success", i), prefix="success: ") from None

    def _check_success(self, header: MissionHeader, source: YamlSource, scene: SceneConfig | None) -> None:
        """Success conditions name what the run will have: places, surfaces, and objects of the world or its
        scene ("coke 2", a scene's second coke: judged in ground truth, so it must be there)."""
        world = self.checks.world
        surfaces, places = world.surfaces, world.places
        objects = [name for name, o in world.objects.items() if o.body is not None]  # the world's fixed bodies
        objects += [name for name, _ in scene.instances()] if scene is not None else []
        for i, condition in enumerate(header.success):
            data = condition.model_dump()
            kind = next(k for k in CONDITION_KINDS if k in data)
            where = source.where(("success", i, kind))
            names: list[tuple[str, dict]] = []
            if kind == "on":
                names = [(data["on"][0], objects), (data["on"][1], surfaces)]
            elif kind == "inside":
                names = [(data["inside"][0], objects), (data["inside"][1], world.containers)]
            elif kind == "at":
                target = data["at"] if isinstance(data["at"], str) else data["at"]["place"]
                names = [(target, places)]
            elif kind in ("in_hand", "upright", "delivered"):
                names = [(data[kind], objects)]
            elif kind == "near":
                names = [(data["near"]["object"], objects)]
            for name, valid in names:
                if name in valid:
                    continue
                if valid is objects and world.object_of(name) is not None:
                    in_scene = f"scene '{scene.name}'" if scene is not None else f"world '{world.name}' (no scene)"
                    raise UserError(
                        f"success: no '{name}' in {in_scene}: a condition is judged on the objects the run has",
                        where=where,
                        hint=did_you_mean(name, valid) if valid else "the scene places no objects",
                    )
                raise UserError(f"success: unknown name '{name}'", where=where, hint=did_you_mean(name, valid))

    def _skill_recovery(self, header: MissionHeader, source: YamlSource) -> dict[str, NodeSpec]:
        """Check the per-skill recovery names; load their alternatives (one spec, compiled at each use)."""
        alternatives = {}
        for skill_name in header.recovery.skills:
            ypath = ("recovery", "skills", skill_name)
            if skill_name not in REGISTRY:
                raise UserError(
                    f"recovery: unknown skill '{skill_name}'",
                    where=source.where(ypath),
                    hint=did_you_mean(skill_name, REGISTRY),
                )
            raw = source.data["recovery"]["skills"][skill_name]
            _, alternative = self._recovery(raw, source, ypath, f"recovery.{skill_name}", stack=())
            if alternative is not None:
                alternatives[skill_name] = alternative
        return alternatives


def _config_at(load: Callable[[str], Any], name: str, source: YamlSource, field: str) -> Any:
    """Load a robot or world config; an unknown name is reported at the mission's line naming it."""
    try:
        return load(name)
    except UserError as error:
        if error.message.startswith("unknown"):
            error.where = source.where((field,))
        raise
