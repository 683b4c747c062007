"""Evolving toward what is in the scene (Poncin's automata): a mesh the artist places and
scales is the target surface the branch ends should lie on, boxes marked favoured or
forbidden are cells of his density grid, which count leaves. Or toward a picture of the
tree, seen from the active camera: its outline, as `sylva match` matches one. The run goes
on a worker thread, with progress in the status bar and the best plant so far in the
viewport.

The scene is turned into a config of the automata model, as `examples/automata/sphere.toml`
and `box-above.toml` write one by hand: the paper's typical run (two automata, 100
iterations, about 30 branch ends) at the paper's scale, where the target's largest half
extent is 150 units; a unit is then that many metres, so a plant evolved for a 2 m bush and
one for a 20 m tree grow alike.
"""

import math
import os
import threading

import bpy
from mathutils import Vector

from . import plants

ZONE = "sylva_zone"  # on a mesh object: "favoured" or "forbidden"
PAPER_RADIUS = 150.0  # units: the paper's target sphere
SHAPES = ("SPHERE", "BOX", "CYLINDER", "CONE")
# What Blender's Add > Mesh names each primitive's data, for Shape: Auto.
PRIMITIVES = {"Sphere": "SPHERE", "Icosphere": "SPHERE", "Cube": "BOX", "Cylinder": "CYLINDER",
              "Cone": "CONE"}


class SceneError(ValueError):
    """The scene does not make a run: no target, a shape not known, a zone outside."""


def shape_of(obj, choice):
    """The target's shape: `choice`, or with AUTO the primitive its mesh was added as."""
    if choice != "AUTO":
        return choice
    name = obj.data.name.split(".")[0]
    if name not in PRIMITIVES:
        raise SceneError(f"Cannot tell the shape of {obj.name} (mesh '{obj.data.name}'): choose "
                         "Sphere, Box, Cylinder or Cone as the target's shape")
    return PRIMITIVES[name]


def _bounds(obj, origin):
    """Lowest and highest corners of `obj`'s world bounding box in Sylva's frame (Y up),
    metres from `origin` (where the plant stands)."""
    corners = [obj.matrix_world @ Vector(c) - origin for c in obj.bound_box]
    sylva = [(c.x, c.z, -c.y) for c in corners]
    return [min(p[i] for p in sylva) for i in range(3)], [max(p[i] for p in sylva) for i in range(3)]


def target_table(obj, shape, origin):
    """([automata.fitness.target] in metres, the half extent that sets the scale)."""
    lo, hi = _bounds(obj, origin)
    half = [(h - l) / 2 for l, h in zip(lo, hi)]
    centre = [(h + l) / 2 for l, h in zip(lo, hi)]
    if min(half) <= 0:
        raise SceneError(f"The target {obj.name} is flat ({2 * half[0]:.2f} x {2 * half[2]:.2f} x "
                         f"{2 * half[1]:.2f} m): give it a volume")
    if shape == "SPHERE":
        if max(half) - min(half) <= 0.02 * max(half):
            table = {"shape": "sphere", "center": centre, "radius": sum(half) / 3}
        else:
            table = {"shape": "ellipsoid", "center": centre, "radii": half}
    elif shape == "BOX":
        table = {"shape": "box", "center": centre, "size": [2 * h for h in half]}
    else:
        table = {"shape": shape.lower(), "base": [centre[0], lo[1], centre[2]],
                 "radius": (half[0] + half[2]) / 2, "height": hi[1] - lo[1]}
    return table, max(half)


def _scaled(table, unit):
    out = {}
    for key, value in table.items():
        if isinstance(value, list):
            out[key] = [v / unit for v in value]
        elif isinstance(value, float):
            out[key] = value / unit
        else:
            out[key] = value
    return out


def grid_table(zones, target, origin, unit, divisions=5):
    """[automata.fitness.grid] in units: a grid over the target and the zones, each zone
    the box of cells it overlaps, weight 1 if favoured and -1 if forbidden; other cells
    count for nothing."""
    boxes = [(zone, *_bounds(zone, origin)) for zone in zones]
    lo, hi = _bounds(target, origin)
    for _, zlo, zhi in boxes:
        lo = [min(a, b) for a, b in zip(lo, zlo)]
        hi = [max(a, b) for a, b in zip(hi, zhi)]
    lo[1] = max(lo[1], 0.0)  # nothing grows below the ground
    if any(h <= l for l, h in zip(lo, hi)):
        raise SceneError("The favoured and forbidden boxes are all below the ground")
    cell = [(h - l) / divisions for l, h in zip(lo, hi)]
    table = {"min": [v / unit for v in lo], "max": [v / unit for v in hi],
             "divisions": [divisions] * 3, "weight": 0.0, "boxes": []}
    for zone, zlo, zhi in boxes:
        first = [min(max(int((a - l) / c), 0), divisions - 1) for a, l, c in zip(zlo, lo, cell)]
        last = [min(max(int(-(-(b - l) // c)) - 1, 0), divisions - 1) for b, l, c in zip(zhi, lo, cell)]
        weight = 1.0 if zone[ZONE] == "favoured" else -1.0
        table["boxes"].append({"from": first, "to": [max(f, t) for f, t in zip(first, last)],
                               "weight": weight})
    return table


def config(target, shape, zones, origin, generations, population, seed, branches=30):
    """The automata config the scene asks for (a dict, as `sylva.Config.from_dict` reads)."""
    table, half = target_table(target, shape_of(target, shape), origin)
    unit = half / PAPER_RADIUS
    fitness = {
        "unit": unit,
        "num_target": branches,
        "endpoints": "axes",
        "weights": {"pos": 5.0, "num": 50.0, "dist": 200.0, "thick": 0.0, "angle": 0.0,
                    "grid": 10.0 if zones else 0.0},
        "target": _scaled(table, unit),
    }
    growth = {"iterations": 100, "root_length": 2.5, "unit": unit}
    if zones:
        fitness["grid"] = grid_table(zones, target, origin, unit)
        fitness["grid_gate"] = 1500.0
        growth["leaf_length"] = 10.0
    return {
        "model": "automata",
        "run": {"generations": generations, "population": population, "seed": seed},
        "automata": {
            "automata": 2,
            "breeding": {"mutation": 0.1, "reproduction": 0.02, "reevaluate": False},
            "growth": growth,
            "fitness": fitness,
        },
    }


def zones_in(scene):
    return [obj for obj in scene.objects if obj.get(ZONE) in ("favoured", "forbidden")]


# The run ------------------------------------------------------------------------------------


class Run:
    """One evolution on a worker thread. The thread only calls the package (which releases
    the GIL while it works); Blender's thread reads `progress()` and shows it."""

    def __init__(self, config_dict, generations):
        s = plants.sylva()
        self.run = s.Evolution(s.Config.from_dict(config_dict))
        self.generations = generations
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._done = 0
        self._best = None
        self._plant = None
        self._error = None
        self._thread = threading.Thread(target=self._work, name="sylva evolve", daemon=True)

    def start(self):
        self._thread.start()
        return self

    def _work(self):
        try:
            for _ in range(self.generations):
                if self._stop.is_set():
                    break
                self.run.step()
                best = self.run.best()
                # Grown here, off Blender's thread, as the run's files grow it (pruned to a
                # picture's outline, as the run scored it).
                shown = self._best
                plant = None if shown is not None and shown.id == best.id else plants.grow_member(self.run, best)
                with self._lock:
                    self._done += 1
                    if plant is not None:
                        self._best, self._plant = best, plant
        except Exception as e:  # shown in the status bar and the report
            with self._lock:
                self._error = f"{type(e).__name__}: {e}"

    def stop(self):
        self._stop.set()

    def progress(self):
        """(generations done, best member so far or None, its plant, error or None, still
        running)."""
        with self._lock:
            return self._done, self._best, self._plant, self._error, self._thread.is_alive()

    def join(self):
        self._thread.join()


# The run going on ("run"), the name of the object showing its best plant ("object"), the id of the
# member shown ("shown"), the target's name, the status text, and the run before ("last").
_current = {}


def running():
    run = _current.get("run")
    return run is not None and run.progress()[4]


def begin(context, target, shape, zones, generations, population, seed, branches):
    """Starts a run toward `target` and the zones, the plant standing at the 3D cursor, and
    makes the object that will show its best plant. Returns the object."""
    origin = context.scene.cursor.location.copy()
    made = config(target, shape, zones, origin, generations, population, seed, branches)
    return _begin(context, made, generations, target.name)


def picture_config(path, model, generations, population, seed):
    """The config of a run toward a picture's outline (the outline alone decides, as
    `sylva match` runs it)."""
    return {
        "model": model,
        "run": {"generations": generations, "population": population, "seed": seed},
        "match": {"front": path, "beside": False},
    }


def begin_picture(context, path, model, generations, population, seed):
    """Starts a run toward the outline of the picture at `path`, seen from the active camera:
    the plant stands at the 3D cursor, turned so that the side Sylva matched (its front)
    faces the camera. Returns the object."""
    made = picture_config(path, model, generations, population, seed)
    obj = _begin(context, made, generations, os.path.basename(path))
    camera = context.scene.camera
    if camera is not None:
        to_camera = camera.matrix_world.translation - obj.location
        # Sylva's front view looks along its -Z, Blender's +Y: the front faces -Y.
        obj.rotation_euler = (0.0, 0.0, math.atan2(to_camera.y, to_camera.x) + math.pi / 2)
    return obj


def _begin(context, made, generations, target_name):
    if running():
        raise SceneError("A run is going on: stop it first")
    run = Run(made, generations)
    obj = plants.new_object(context, f"Sylva evolved toward {target_name}")
    obj.location = context.scene.cursor.location
    # By name: an undo or a reload makes new Python objects of the same data.
    _current.update(run=run.start(), object=obj.name, shown=None, target=target_name)
    return obj


def tick():
    """Shows the run's progress: the status bar's text and, when a better plant turns up,
    that plant in the viewport. Registered with bpy.app.timers while a run goes on: returns
    the seconds until the next look, or None once the run has ended."""
    run, obj = _current.get("run"), bpy.data.objects.get(_current.get("object", ""))
    if run is None:
        return None
    done, best, plant, error, alive = run.progress()
    if obj is not None and best is not None and best.id != _current["shown"]:
        plants.set_plant(obj, best.genome, plant, {"operator": "evolve", "generation": best.generation})
        obj[plants.SOURCE] = f"evolved toward {_current['target']}"
        obj["sylva_fitness"] = best.fitness
        _current["shown"] = best.id
    text = status(done, run.generations, best, error, alive)
    _status(text)
    _current["text"] = text
    if alive:
        return 0.25
    _current["run"], _current["last"] = None, run
    bpy.app.timers.register(lambda: _status(None), first_interval=5.0)  # then Blender's own
    return None


def status(done, generations, best, error, alive):
    if error:
        return f"Sylva: the run stopped: {error}"
    shown = "" if best is None else f", best fitness {best.fitness:.4g}"
    state = "evolving" if alive else "evolved"
    return f"Sylva {state}: generation {done} of {generations}{shown}"


def _status(text):
    """The status bar's text (None gives it back to Blender). Without a window (bpy as a
    module) there is no status bar: the text is kept in last_status() instead."""
    try:
        for window in bpy.context.window_manager.windows:
            window.workspace.status_text_set(text)
            for area in window.screen.areas:  # the Evolve panel shows the text too
                if area.type == "VIEW_3D":
                    area.tag_redraw()
    except (AttributeError, RuntimeError):
        pass


def last_status():
    return _current.get("text")


def stop():
    run = _current.get("run")
    if run is not None:
        run.stop()
