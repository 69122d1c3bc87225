// Placeholder: implemented in the pendulum module work.
