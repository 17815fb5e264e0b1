"""The grounds a ring meets: half-planes and drums, their prescribed motion, the contact
constraints with Coulomb friction inside the Newton system, and the prediction of a ring's first
touch of a ground."""
