# by hand: version 5, errors and the correlations of the six terms
pm-model 5
mount equatorial
order 0
errors
correlations
stars_sigma 1.2e-6
terms 6
term a 1 0 0 1e-4 2.5e-6
term b 2 0 0 -2e-4 2.5e-6
term c' 3 0 0 0.001 1e-5
term d 4 0 0 0 3e-6
term e' 5 0 0 -0.0005 1e-6
term i 6 0 0 3.5e-05 4e-6
corr 2 1 -0.25
corr 3 1 0.1 0.2
corr 4 1 0 0 -0.5
corr 5 1 0.05 0 0 0.3
corr 6 1 0 0.1 -0.9 0.4 0
end
