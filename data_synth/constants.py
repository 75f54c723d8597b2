"""Every constant of ``data_synth`` in one place: sizes, tolerances and default counts.

Lengths are in metres for the humanoid, hand and face (so a body is about 1.75 high); the flag and
the bar use their own unit lengths. Resolutions are *approximate vertex counts* of a template.
"""

# --- template meshing (implicit surface -> triangle mesh) -------------------------------------
#: vertices per unit surface area times squared grid spacing, measured for marching cubes
#: followed by relaxation; used to pick the grid spacing for a target vertex count.
MC_VERTEX_DENSITY = 0.88
#: extra grid cells around the bounding box of the implicit surface (keeps the surface closed).
MC_PADDING_CELLS = 3
#: half-width, in coarse grid cells, of the band around the surface where the implicit function
#: is evaluated exactly (elsewhere only its sign, from a grid twice as coarse, is kept).
NARROW_BAND_CELLS = 2.5
#: tangential relaxation rounds after marching cubes.
RELAX_ITERATIONS = 25
#: step of one relaxation round (fraction of the move towards the one-ring centroid).
RELAX_STEP = 0.6
#: Newton steps that pull the relaxed vertices back onto the implicit surface at the end (one
#: step follows every relaxation round).
REPROJECT_STEPS = 3
#: finite-difference step for implicit-function gradients, in units of the grid spacing.
GRADIENT_STEP = 0.25
#: edges shorter than this fraction of the mean edge length are collapsed after marching cubes.
SHORT_EDGE_FRACTION = 0.3

# --- quality limits the generators guarantee (and the tests check) -----------------------------
#: every triangle keeps at least this fraction of its rest-pose area in every frame.
MIN_AREA_RATIO = 0.1
#: and at most this multiple of it.
MAX_AREA_RATIO = 8.0
#: every edge keeps its length within [MIN_EDGE_RATIO, MAX_EDGE_RATIO] x its rest length.
MIN_EDGE_RATIO = 0.2
MAX_EDGE_RATIO = 5.0
#: the normals of two triangles sharing an edge differ by less than this (degrees) in every
#: frame: a larger angle means a triangle folded over (inverted) or a pinched crease.
MAX_FOLD_ANGLE_DEG = 150.0
#: and less than this in the rest pose (thin parts such as fingertips make sharper creases).
MAX_TEMPLATE_FOLD_DEG = 140.0
#: smallest interior angle (degrees) of any template triangle.
MIN_TEMPLATE_ANGLE_DEG = 10.0
#: two meshes are the same mesh when every vertex lies within this fraction of the bounding-box
#: diagonal of its counterpart (quality.duplicate_pairs).
DUPLICATE_MESH_RTOL = 1e-6
#: the linear floor a stand-in collection must reach (issue 24; benchmarks/bench_synth_floor.py): PCA
#: on coordinates, every direction the training meshes span, every 5th mesh held out, at least this
#: fraction of the bounding-box diagonal; the pose collections at least POSE_FLOOR_TARGET (a real
#: scanned body in 71 poses: 8e-3).
FLOOR_TARGET = 1e-4
POSE_FLOOR_TARGET = 2e-3
POSE_COLLECTIONS = ("scape", "dyna", "hand", "face")

# --- humanoid ---------------------------------------------------------------------------------
#: default and allowed vertex counts of the body template.
HUMANOID_DEFAULT_RESOLUTION = 2500
MIN_RESOLUTION = 300
MAX_RESOLUTION = 40000
#: rest pose: arms this many degrees below horizontal (an A-pose keeps arms off the torso).
ARM_REST_ANGLE_DEG = 45.0
#: smooth-union blend radius of the body's implicit primitives (metres).
BODY_BLEND_RADIUS = 0.035
#: width (metres) over which skinning weights blend across a joint.
SKIN_BLEND_WIDTH = 0.12
#: left/right bones fade out between this distance (metres) on their own side of the body's
#: midline and the same distance on the other side.
SKIN_MIDLINE_WIDTH = 0.04
#: default number of poses in the SCAPE-like collection (the paper's SCAPE has 71).
SCAPE_N_POSES = 71
#: default number of frames of the jumping-jacks sequence (Vlasic's Jumping has 150).
JUMPING_N_FRAMES = 120
#: default frames per motion in the Dyna-like collection.
DYNA_FRAMES_PER_MOTION = 6
#: jumping jacks in the Jumping-like sequence: 10 frames each at the default length, like a capture
#: at about 8 frames per second (at 30 any smooth sequence is linear data: every frame is a
#: combination of its neighbours; measured, 5 jacks in 120 frames: PCA floor 2e-6 of the diagonal).
JUMPING_REPS = 12
#: the arms' "lower" angle (radians from the A-pose) when they hang down, with room for a
#: performer's variation before an upper arm passes into the torso (measured in the rest pose: 0.55
#: is clear for all five Dyna shapes, 0.62 is not for the heavy ones).
ARM_DOWN = 0.4
#: how far jumping jacks raise the arms from ARM_DOWN (radians; 2.5 with the shrug pushes the upper
#: arms into a slim head).
JACKS_ARM_RAISE = 1.95
#: a performer never repeats a motion exactly: smooth random rotations (radians, RMS, about each of
#: the three axes) added to every joint of a motion by ``Pose.vary``, and the highest frequency of
#: those signals in cycles per pass of the motion.
PERFORMANCE_RANGE = {
    "spine": 0.05, "chest": 0.05, "neck": 0.08, "head": 0.15,
    "clavicle": 0.05, "upperarm": 0.12, "forearm": 0.12, "hand": 0.3,
    "thigh": 0.05, "shin": 0.06, "foot": 0.12,
}
PERFORMANCE_CYCLES = 6
#: the skeleton check of poses (``motions.limb_clearance``): the least distance (metres) between
#: the two arms, and between an arm or a hand and the centre of the head, that a pose may keep
#: (the head is 0.16 m wide, an upper arm 0.1 m thick, a hand 0.09 m wide).
ARM_ARM_CLEARANCE = 0.12
ARM_HEAD_CLEARANCE = 0.13
HAND_HEAD_CLEARANCE = 0.16
#: where the head's centre lies from the head joint in the rest pose (metres).
HEAD_CENTRE_OFFSET = (0.0, 0.095, 0.015)
#: the SCAPE-like poses' independent per-joint variation, in units of PERFORMANCE_RANGE.
SCAPE_VARY = 1.0
#: the Dyna-like and Jumping-like performers' variation (units of PERFORMANCE_RANGE) and, for the
#: jumping sequence, its highest frequency in cycles per pass.
DYNA_VARY = 1.0
JUMPING_VARY = 1.2
JUMPING_CYCLES = 40
#: how many times a body collection redraws a motion whose frames fail the skeleton check.
POSE_DRAWS = 50

# --- hand and face ----------------------------------------------------------------------------
HAND_DEFAULT_RESOLUTION = 1800
HAND_BLEND_RADIUS = 0.006
HAND_SKIN_BLEND_WIDTH = 0.016
#: the hand collection: meshes per gesture, each an independent draw around the gesture's pose: its
#: curls scaled by U(HAND_MIN_AMOUNT, 1), every joint moved by up to HAND_JOINT_JITTER of its range,
#: the spread by up to HAND_SPREAD_JITTER, and the wrist's flexion, deviation and pronation by up
#: to HAND_WRIST_RANGE radians (small enough for every gesture to stay recognisable)
HAND_VARIANTS = 10
HAND_MIN_AMOUNT = 0.85
HAND_JOINT_JITTER = 0.15
HAND_SPREAD_JITTER = 0.3
HAND_WRIST_RANGE = (0.4, 0.25, 0.6)
#: the flag's pole (scenery for renderings, not part of the mesh): radius, bottom and top, in the
#: flag's units (the sheet is 1 high, from y = 0 to 1)
FLAG_POLE_RADIUS = 0.02
FLAG_POLE_BOTTOM = -0.6
FLAG_POLE_TOP = 1.06
FLAG_POLE_COLOR = "#7a6a58"
#: scale of the face's local blendshapes (mouth, brows, cheeks, lips) and the jaw's opening angle in
#: radians: large enough for the expressions to read apart at gallery size, without self-intersections
FACE_BLENDSHAPE_SCALE = 1.7
FACE_JAW_ANGLE = 0.34
FACE_DEFAULT_RESOLUTION = 2000
#: the face collection: meshes per expression, each drawing its intensity in [FACE_MIN_INTENSITY, 1],
#: every blendshape weight within +-FACE_WEIGHT_JITTER of its share and an extra jaw opening of up to
#: FACE_SPEECH_JAW radians (speech); the jaw never opens past FACE_JAW_ANGLE
FACE_VARIANTS = 10
FACE_MIN_INTENSITY = 0.6
FACE_WEIGHT_JITTER = 0.2
FACE_SPEECH_JAW = 0.06
#: every mesh also moves every other blendshape by up to FACE_SPEECH_WEIGHT (speech and mood: a face in
#: a capture is never still), rolls its lips by up to FACE_LIP_ROLL radians at weight 1 (an expression's
#: "lip_roll" weight scales it), slides its jaw sideways by up to FACE_JAW_SIDE radians, and turns its
#: head on the neck about FACE_NECK_PIVOT by independent yaw, pitch (up, down) and roll of up to
#: FACE_HEAD_TURN radians: the head's turn times the expression is what no linear basis reproduces
FACE_SPEECH_WEIGHT = 0.35
FACE_ASYMMETRY = 0.3
FACE_LIP_ROLL = 0.5
FACE_JAW_SIDE = 0.03
FACE_NECK_PIVOT = (0.0, -0.11, -0.025)
FACE_HEAD_TURN = (0.6, 0.3, 0.15, 0.2)
FACE_BLEND_RADIUS = 0.02

# --- flag and bar -----------------------------------------------------------------------------
FLAG_DEFAULT_RESOLUTION = 1200
FLAG_ASPECT = 1.5
FLAG_N_FRAMES = 100
#: frames per second of the flag, its wind's travelling waves, their total amplitude (radians of yaw
#: at the free end, before the gust) and their shortest wavelength (in the sheet's height)
FLAG_FPS = 8.0
FLAG_WIND_MODES = 24
FLAG_WAVE_AMPLITUDE = 1.6
FLAG_MIN_WAVELENGTH = 0.3
BAR_DEFAULT_RESOLUTION = 1000
BAR_LENGTH = 4.0
BAR_RADIUS = 0.35
#: exponent of the bar's superellipse cross section (2: circle; larger: squarer).
BAR_SQUARENESS = 4.0
#: meshes per motion of the bar, each an independent draw of its profiles
BAR_VARIANTS = 20
#: spread (standard deviation, degrees) of the bar's profile modes: rows twist, bend (in each of the
#: two planes); columns the constant, linear and quadratic mode along the bar
BAR_PROFILE_DEG = ((150.0, 120.0, 60.0), (100.0, 80.0, 40.0))
#: the draws are clipped at this many standard deviations (a larger bend can loop the tube into itself)
BAR_PROFILE_CLIP = 1.6
#: the large collection of known degrees of freedom (``bodies.make_poses``): how many poses, and each
#: named joint angle's range (radians; drawn uniformly and independently in [low, high]). Sixteen
#: angles: four per arm (lower from the A-pose, swing forward, twist, elbow), two per leg (hip,
#: knee), and the trunk's bend and twist with the head's nod and turn.
POSES_N = 1200
#: poses_dof draws at most this many batches of n poses; ranges that reject nearly every pose fail loudly.
POSES_MAX_DRAWS = 20
POSES_DOF = {
    "l_arm_lower": (-0.9, 0.25), "l_arm_forward": (-0.3, 0.9), "l_arm_twist": (-0.6, 0.6), "l_elbow": (0.0, 1.6),
    "r_arm_lower": (-0.9, 0.25), "r_arm_forward": (-0.3, 0.9), "r_arm_twist": (-0.6, 0.6), "r_elbow": (0.0, 1.6),
    "l_hip": (-0.35, 0.8), "l_knee": (0.0, 1.1), "r_hip": (-0.35, 0.8), "r_knee": (0.0, 1.1),
    "trunk_bend": (-0.1, 0.45), "trunk_twist": (-0.5, 0.5), "head_nod": (-0.15, 0.35), "head_turn": (-0.7, 0.7),
}
