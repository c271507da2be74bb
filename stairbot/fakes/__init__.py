"""stairbot.fakes: the simulated robot (pymunk world, sensor and motor models).

The robot URL ``sim://`` opens :func:`stairbot.fakes.sim.open_sim_robot`.

Modules:

* :mod:`~stairbot.fakes.stairs` -- the stairs as one side-view polyline (floor,
  risers and treads, a landing or a wall at the top) and ray casts against it;
* :mod:`~stairbot.fakes.world_params` -- the physics and instability settings;
* :mod:`~stairbot.fakes.world` -- the pymunk side view: x forward, y up,
  gravity -9.81 m/s^2; three box segments with two driven wheels each, two
  lead-screw lifts, friction, and the instability checks (pitch beyond the
  limit, a segment falling, every wheel off every support);
* :mod:`~stairbot.fakes.plan` -- the top view: yaw, lateral position, side
  walls (the whole length or part of it) and the corner geometry the front
  beams see;
* :mod:`~stairbot.fakes.landing` -- the stairwell seen from above as vertical
  faces (side walls, a quarter-turn landing's walls, the second flight's
  risers) for the side pair and the footprint check; flight 1's and flight
  2's frames and the switch between them at 45 degrees on the landing;
* :mod:`~stairbot.fakes.sensors` -- what every sensor shares: its seeded
  noise generator and the scenario's faults;
* :mod:`~stairbot.fakes.sensor_model`, :mod:`~stairbot.fakes.sensor_presets`,
  :mod:`~stairbot.fakes.beams` -- realistic sensor models (a cone of rays,
  timing, range-dependent noise, outliers, dropouts, weak signal, ultrasonic
  incidence loss), their datasheet presets, and the cones' ray casts
  (docs/sensors.md);
* :mod:`~stairbot.fakes.sim_sensors` -- the sensor board: the four distance
  sensors (six with the side pair SSR/SSL) through their models (each
  reading with its age) and the IMU in segment 2 (pitch and pitch rate of
  its body; roll 0: a side view cannot roll);
* :mod:`~stairbot.fakes.sim` -- :class:`SimRobot` (the Robot protocol),
  :class:`SimClock` (the Clock protocol: advancing it steps the physics,
  optionally paced to the wall clock) and the ``sim://`` factory.

What is modelled and what is not:

* the side view carries all the mechanics; the robot drives along its own axis
  in it.  Yaw only enters through the top view: the front beams' geometry and
  the lateral drift of forward motion.  A robot driving at a slant to the
  risers climbs as if square (calibration squares it up first);
* segment 2's right and left wheels share one side-view wheel pair running at
  their mean; their difference turns the robot about segment 2's centre, and
  only while segments 1 and 3 are lifted clear of the ground;
* side walls bound the beams, not the robot's body, and the side view's
  physics holds only the robot's centre line: a footprint check seen from
  above records the first time the body reaches into a wall, or into a riser
  of a landing's second flight (``Truth.wall_contact``), and lets it through;
* on a quarter-turn landing the side view is flight 1's until the robot has
  turned past 45 degrees towards the second flight, then flight 2's
  (:mod:`~stairbot.fakes.landing`);
* lifts are stiff lead screws: they move at the commanded speed up to their
  force limit, hold when stopped, and never coast;
* the same config, scenario (seed) and command sequence give the same run,
  bit for bit: a fixed physics step, no wall-clock input, one noise stream per
  sensor, one sample per physics state.
"""
