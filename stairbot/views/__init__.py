"""What is drawn: the side view of the stairs and the robot's segments
(``side_view``), the top view (``top_view``), and the pose dead-reckoned
from a wired robot's odometry (``reckon``), shared by the console and the
recording.  Pure Python; it builds on the inputs and ``stairbot.hardware``."""
