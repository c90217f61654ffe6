"""Writers below the World: a world's description out as a scene dict (:mod:`~tumble.io.scene_dump`, behind
``World.to_scene``) or MJCF text (:mod:`~tumble.io.mjcf_export`, behind ``World.to_mjcf``). They read a world
through its public interface and its attachments; the readers of those files (``tumble.scene_file``,
``tumble.models``) sit above the World and build one."""
