/* What the singular boundary's candidates (boundary.c) and the bands along it (bands.c)
 * share: the branch quantities' reach of the boundary and their order. */
#ifndef OM_BOUNDARY_H
#define OM_BOUNDARY_H

#define NEAR_BOUNDARY 1e-2 /* |branch quantity| under which a failed candidate is polished */
#define SHOULDER_SIGN 0    /* (SHOULDER or ARM, ELBOW, WRIST) in every family */
#define ELBOW_SIGN 1
#define WRIST_SIGN 2

#endif
